// Properties of the fixed-step loop itself: bounded work, reported limits,
// and the stage that is skipped when nothing touches.
#include <gtest/gtest.h>

#include <cmath>

#include "support.hpp"

namespace {

using namespace vines;

TEST(Loop, SubstepCapIsReportedNotSilent) {
  SceneParams p = test::paper_scene(DeviceKind::kVines, ContactLaw::kKuwabara, 200.0);
  p.loop.max_substeps_per_step = 3;  // far too few for a 9 ms contact in a 5 ms step
  const test::Outcome o = test::run(p, test::elcentro(200.0));
  EXPECT_GT(o.totals.count.cap_hits, 0);
  EXPECT_LE(o.totals.count.max_substeps_in_step, 3);
  EXPECT_TRUE(std::isfinite(o.totals.peak_top));
  EXPECT_TRUE(std::isfinite(o.last.particle_x));
  // With a sufficient cap nothing is hit.
  p.loop.max_substeps_per_step = 4096;
  EXPECT_EQ(test::run(p, test::elcentro(200.0)).totals.count.cap_hits, 0);
}

TEST(Loop, FreeFlightStepsAreNotSubstepped) {
  // 18 contacts of ~9 ms in 53.76 s: at 1 kHz only a small fraction of the
  // 53760 steps may use the sub-stepper.
  const test::Outcome o = test::run(test::paper_scene(DeviceKind::kVines), test::elcentro(1000.0));
  EXPECT_EQ(o.totals.count.steps, 53760);
  EXPECT_LT(o.totals.count.careful_steps, 0.02 * 53760);
  EXPECT_GT(o.totals.count.contact_substeps, 18);
}

TEST(Loop, RestitutionLawLocatesImpactsAndBalancesEnergy) {
  const test::Outcome o =
      test::run(test::paper_scene(DeviceKind::kVines, ContactLaw::kRestitution), test::elcentro(1000.0));
  EXPECT_GT(o.totals.count.contacts, 5);
  EXPECT_LT(o.totals.ledger.relative_residual(), 1e-6);
  EXPECT_GT(o.totals.ledger.contact, 0.0);
  EXPECT_EQ(o.totals.count.cap_hits, 0);
}

}  // namespace
