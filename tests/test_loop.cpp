// Properties of the fixed-step loop itself: bounded work, reported limits,
// and the stage that is skipped when nothing touches.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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

TEST(Loop, NonFiniteSamplesAreHeldAndCounted) {
  for (DeviceKind kind : {DeviceKind::kNone, DeviceKind::kTmd, DeviceKind::kVines}) {
    std::vector<double> a = test::elcentro(1000.0);
    a.resize(8001);
    a[1000] = NAN;
    a[2000] = INFINITY;
    a[2001] = -INFINITY;
    const test::Outcome o = test::run(test::paper_scene(kind), a);
    EXPECT_EQ(o.totals.count.bad_samples, 3);
    EXPECT_EQ(o.totals.count.divergences, 0);
    EXPECT_TRUE(std::isfinite(o.totals.peak_top));
    EXPECT_TRUE(std::isfinite(o.last.x[9]));
    // Holding a sample for a millisecond barely moves the response.
    std::vector<double> clean = test::elcentro(1000.0);
    clean.resize(8001);
    EXPECT_NEAR(o.last.x[9], test::run(test::paper_scene(kind), clean).last.x[9], 1e-3);
  }
}

TEST(Loop, DivergingStepsAreRolledBack) {
  // A finite but absurd sample (1e200 m/s^2) blows the state up: the guard
  // rolls those steps back, the run goes on with the last good state.
  for (DeviceKind kind : {DeviceKind::kNone, DeviceKind::kTmd, DeviceKind::kVines}) {
    std::vector<double> a = test::elcentro(1000.0);
    a.resize(4001);
    a[3000] = 1e200;
    const test::Outcome o = test::run(test::paper_scene(kind), a);
    EXPECT_GE(o.totals.count.divergences, 1);
    EXPECT_TRUE(std::isfinite(o.last.x[9]));
    EXPECT_LT(std::abs(o.last.x[9]), 1.0);
    EXPECT_LT(o.totals.peak_top, 1.0);
    EXPECT_LT(o.totals.ledger.relative_residual(), 1e-3);
  }
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
