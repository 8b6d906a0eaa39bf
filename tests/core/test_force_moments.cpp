// The frame's response to a contact force from the force's moments
// (vines/split/force_moments.hpp), on the paper's 10-story frame with a VI
// NES: a half-sine pulse (the shape of a contact force) inside a step,
// against the modal equations integrated with 200,000 Runge-Kutta steps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "vines/build/build_model.hpp"
#include "vines/model/frame_presets.hpp"
#include "vines/split/force_moments.hpp"

namespace {

using namespace vines;
constexpr double kPi = 3.14159265358979323846;
using M = Model<double, 10, VinesDevice<VinesParams{}.law>>;

const M& frame_model() {
  static M m;
  static const bool ok = [] {
    SceneParams sc;
    apply_frame_preset(FramePreset::kTable1, &sc.frame);
    sc.device.kind = DeviceKind::kVines;
    return build_model(sc, &m).ok();
  }();
  EXPECT_TRUE(ok);
  return m;
}

// A contact-like force: 1 N half-sine from s0 for tc.
double pulse(double s, double s0, double tc) { return s > s0 && s < s0 + tc ? std::sin(kPi * (s - s0) / tc) : 0.0; }

// Largest over the modes of |moments - reference| / |reference| (position
// and velocity) after a step h with the pulse at [0.3 h, 0.7 h], from rest.
double worst_relative_error(double h) {
  const M& m = frame_model();
  const auto fm = fixed::force_moments(m.lti);
  const double s0 = 0.3 * h, tc = 0.4 * h;
  constexpr int kSteps = 200000;
  const double ds = h / kSteps;
  // Moments by Simpson's rule.
  double mu[4] = {};
  for (int i = 0; i <= kSteps; ++i) {
    const double s = i * ds, w = (i == 0 || i == kSteps) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    const double f = pulse(s, s0, tc) * w * ds / 3.0, r = h - s;
    mu[0] += f;
    mu[1] += f * r;
    mu[2] += f * r * r / 2.0;
    mu[3] += f * r * r * r / 6.0;
  }
  M::VecX z = M::VecX::Zero();
  fm.apply(z, mu);
  double worst = 0;
  for (int j = 0; j < 10; ++j) {
    // q'' = ak q + ac q' + bfv F(s), classic Runge-Kutta.
    auto acc = [&](double s, double q, double v) { return m.lti.ak(j) * q + m.lti.ac(j) * v + m.lti.bfv(j) * pulse(s, s0, tc); };
    double q = 0, v = 0;
    for (int i = 0; i < kSteps; ++i) {
      const double s = i * ds;
      const double k1q = v, k1v = acc(s, q, v);
      const double k2q = v + 0.5 * ds * k1v, k2v = acc(s + 0.5 * ds, q + 0.5 * ds * k1q, k2q);
      const double k3q = v + 0.5 * ds * k2v, k3v = acc(s + 0.5 * ds, q + 0.5 * ds * k2q, k3q);
      const double k4q = v + ds * k3v, k4v = acc(s + ds, q + ds * k3q, k4q);
      q += ds / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q);
      v += ds / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    worst = std::fmax(worst, std::fabs(z(j) - q) / std::fabs(q));
    worst = std::fmax(worst, std::fabs(z(M::kP + j) - v) / std::fabs(v));
  }
  return worst;
}

TEST(ForceMoments, FrameResponseToAPulseAt1kHz) {
  const double e1 = worst_relative_error(1e-3), e2 = worst_relative_error(0.5e-3);
  std::printf("half-sine pulse in a step, 10 modes, 4 moments: worst relative error %.3g at h = 1 ms, "
              "%.3g at 0.5 ms (ratio %.1f)\n", e1, e2, e1 / e2);
  EXPECT_LT(e1, 1e-6);       // measured 2.5e-7
  EXPECT_GT(e1 / e2, 6.0);   // third order in the positions: 8 when h halves
}

}  // namespace
