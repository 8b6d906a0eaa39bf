// The same firmware loop in float: close to double where the problem is well
// conditioned (the linear TMD scene, the VI NES peak before chaos sets in).
#include <gtest/gtest.h>

#include <utility>

#include "support.hpp"

namespace {

using namespace vines;

// The paper's El Centro scene with `kind`, in double and in float.
std::pair<test::Outcome, test::Outcome> double_and_float(DeviceKind kind) {
  const auto a = test::elcentro(1000.0);
  const SceneParams p = test::paper_scene(kind);
  return {test::run(p, a, host::Scalar::kDouble), test::run(p, a, host::Scalar::kFloat)};
}

TEST(Scalar, FloatTracksDoubleOnTheTmdScene) {
  const auto [d, f] = double_and_float(DeviceKind::kTmd);
  EXPECT_NEAR(f.totals.peak_top / d.totals.peak_top, 1.0, 1e-4);
  EXPECT_NEAR(f.totals.elastic_energy / d.totals.elastic_energy, 1.0, 1e-3);
  EXPECT_LT(f.totals.ledger.relative_residual(), 1e-4);
}

TEST(Scalar, FloatTracksDoubleOnTheVinesPeak) {
  const auto [d, f] = double_and_float(DeviceKind::kVines);
  // The peak (t = 5.57 s, after 5 contacts) is well conditioned.
  EXPECT_NEAR(f.totals.peak_top / d.totals.peak_top, 1.0, 1e-3);
  EXPECT_NEAR(f.totals.t_peak_top, d.totals.t_peak_top, 0.01);
  EXPECT_LT(f.totals.ledger.relative_residual(), 1e-4);
  EXPECT_EQ(f.totals.count.cap_hits, 0);
}

}  // namespace
