// Reproduction of the paper's El Centro results with the settings of
// docs/model.md (section 10, choices; section 12, figures).
#include <gtest/gtest.h>

#include "support.hpp"

namespace {

using namespace vines;
using vines::test::Outcome;

struct Paper : ::testing::Test {
  static void SetUpTestSuite() {
    const auto a = test::elcentro(1000.0);
    bare = test::run(test::paper_scene(DeviceKind::kNone), a);
    tmd = test::run(test::paper_scene(DeviceKind::kTmd), a);
    vines = test::run(test::paper_scene(DeviceKind::kVines), a);
  }
  static double x_r(const Outcome& o) { return 1.0 - o.totals.peak_top / bare.totals.peak_top; }
  static double e_r(const Outcome& o) {
    return 1.0 - o.totals.elastic_energy / bare.totals.elastic_energy;
  }
  static Outcome bare, tmd, vines;
};
Outcome Paper::bare, Paper::tmd, Paper::vines;

TEST_F(Paper, TmdReductions) {
  EXPECT_NEAR(x_r(tmd), 0.131, 0.01);
  EXPECT_NEAR(e_r(tmd), 0.775, 0.015);
}

TEST_F(Paper, VinesReductionsAtRestBeta135) {
  EXPECT_NEAR(x_r(vines), 0.292, 0.025);
  EXPECT_NEAR(e_r(vines), 0.672, 0.025);
}

TEST_F(Paper, VinesTimeScalesOfModelMd) {
  // 18 contacts, deepest overlap about 2.9 mm, peak top displacement at 5.57 s.
  EXPECT_EQ(vines.totals.count.contacts, 18);
  EXPECT_NEAR(vines.totals.max_overlap, 2.9e-3, 0.1e-3);
  EXPECT_NEAR(vines.totals.t_peak_top, 5.57, 0.01);
  EXPECT_EQ(vines.totals.count.cap_hits, 0);
}

TEST_F(Paper, DevicesReducePeaksOnEveryFloor) {
  // Fig. 9: both devices lower the peak displacement of the upper floors.
  for (int i = 5; i < 10; ++i) {
    EXPECT_LT(vines.totals.peak_x[i], bare.totals.peak_x[i]) << "floor " << i + 1;
    EXPECT_LT(tmd.totals.peak_x[i], bare.totals.peak_x[i]) << "floor " << i + 1;
  }
}

}  // namespace
