// Convergence of the fixed-step loop on El Centro, through the host engine.
// The linear part is discretised exactly for a ground acceleration that is
// linear between samples, so with a piecewise-linear record every sensor rate
// aligned with the record's knots gives the same answer (to rounding); the
// contact tolerance controls the contact error. (Against analytic inputs:
// tests/core/test_sine_convergence.cpp.)
#include <gtest/gtest.h>

#include <cmath>

#include "support.hpp"

namespace {

using namespace vines;

TEST(Convergence, BareFrameIsExactForPiecewiseLinearInput) {
  const test::Outcome o50 = test::run(test::paper_scene(DeviceKind::kNone, {}, 50), test::elcentro(50));
  const test::Outcome o1k =
      test::run(test::paper_scene(DeviceKind::kNone, {}, 1000), test::elcentro(1000));
  EXPECT_NEAR(o50.totals.peak_top / o1k.totals.peak_top, 1.0, 1e-9);
  EXPECT_NEAR(o50.totals.elastic_energy / o1k.totals.elastic_energy, 1.0, 1e-10);
  EXPECT_NEAR(o50.last.x[9], o1k.last.x[9], 1e-12);
}

TEST(Convergence, ContactToleranceControlsTheContactError) {
  // Same input and rate, tighter contact tolerance: the answer settles.
  const auto a = test::elcentro(200.0);
  auto peak = [&](double rtol) {
    SceneParams p = test::paper_scene(DeviceKind::kVines, ContactLaw::kKuwabara, 200.0);
    p.loop.contact_rtol = rtol;
    return test::run(p, a).totals.peak_top;
  };
  const double p6 = peak(1e-6), p9 = peak(1e-9), p12 = peak(1e-12);
  EXPECT_LT(std::abs(p9 - p12), std::abs(p6 - p12) + 1e-15);
  EXPECT_LT(std::abs(p9 - p12) / p12, 1e-6);
}

}  // namespace
