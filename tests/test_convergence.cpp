// Convergence of the fixed-step loop. The linear part is discretised exactly
// for a ground acceleration that is linear between samples, so
//  - with a piecewise-linear record, every sensor rate aligned with the
//    record's knots gives the same answer (to rounding);
//  - with a smooth ground motion, the only error is the linear interpolation
//    of the samples: second order in the sensor period, against the analytic
//    solution;
//  - with the VI NES, halving the period keeps that order through contacts.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <vector>

#include "support.hpp"
#include "vines/frame.hpp"

namespace {

using namespace vines;
constexpr double kPi = 3.14159265358979323846;

std::vector<double> sine(double amp, double freq_hz, double rate_hz, double duration) {
  const auto n = static_cast<std::size_t>(std::llround(duration * rate_hz));
  std::vector<double> a(n + 1);
  for (std::size_t k = 0; k <= n; ++k) a[k] = amp * std::sin(2 * kPi * freq_hz * (k / rate_hz));
  return a;
}

// Top-floor displacement at t of the frame at rest under a_g = amp sin(W t),
// mode by mode in closed form (particular + free response).
double analytic_top(const SceneParams& p, double amp, double freq_hz, double t) {
  const Modal<10> md = modal_analysis(build_frame<10>(p.frame));
  const double w_f = 2 * kPi * freq_hz;
  double x = 0;
  for (int j = 0; j < 10; ++j) {
    const double w = md.omega(j), z = md.zeta(j), wd = w * std::sqrt(1 - z * z);
    const std::complex<double> h = 1.0 / std::complex<double>(w * w - w_f * w_f, 2 * z * w * w_f);
    const std::complex<double> c = -md.gamma(j) * amp * h;  // q_p = Im(c e^{iWt})
    auto qp = [&](double tt) { return std::imag(c * std::exp(std::complex<double>(0, w_f * tt))); };
    const double qp0 = std::imag(c), dqp0 = std::imag(c * std::complex<double>(0, w_f));
    const double c1 = -qp0, c2 = (-dqp0 + z * w * c1) / wd;
    const double q = qp(t) + std::exp(-z * w * t) * (c1 * std::cos(wd * t) + c2 * std::sin(wd * t));
    x += md.phi(9, j) * q;
  }
  return x;
}

TEST(Convergence, BareFrameIsExactForPiecewiseLinearInput) {
  const test::Outcome o50 = test::run(test::paper_scene(DeviceKind::kNone, {}, 50), test::elcentro(50));
  const test::Outcome o1k =
      test::run(test::paper_scene(DeviceKind::kNone, {}, 1000), test::elcentro(1000));
  EXPECT_NEAR(o50.totals.peak_top / o1k.totals.peak_top, 1.0, 1e-9);
  EXPECT_NEAR(o50.totals.elastic_energy / o1k.totals.elastic_energy, 1.0, 1e-10);
  EXPECT_NEAR(o50.last.x[9], o1k.last.x[9], 1e-12);
}

TEST(Convergence, BareFrameIsSecondOrderForSmoothInput) {
  const double amp = 1.0, f = 1.3, t_end = 8.0;
  const double exact = analytic_top(test::paper_scene(DeviceKind::kNone), amp, f, t_end);
  std::vector<double> err;
  for (double rate : {25.0, 50.0, 100.0, 200.0}) {
    const test::Outcome o =
        test::run(test::paper_scene(DeviceKind::kNone, {}, rate), sine(amp, f, rate, t_end));
    err.push_back(std::abs(o.last.x[9] - exact));
  }
  for (std::size_t i = 1; i < err.size(); ++i) {
    const double order = std::log2(err[i - 1] / err[i]);
    EXPECT_NEAR(order, 2.0, 0.15) << "step " << i << ": errors " << err[i - 1] << " " << err[i];
  }
  // Linear interpolation of a sine misses it by up to (W h)^2 / 8 of its amplitude.
  const double wh = 2 * kPi * f / 200.0;
  EXPECT_LT(err.back(), wh * wh / 8 * std::abs(exact));
}

TEST(Convergence, VinesThroughItsFirstContactsIsSecondOrder) {
  // Near-resonant sine: the particle hits both walls within a few seconds.
  const double amp = 2.0, f = 0.5, t_end = 7.0;
  auto at = [&](double rate) {
    SceneParams p = test::paper_scene(DeviceKind::kVines, ContactLaw::kKuwabara, rate);
    p.loop.contact_rtol = 1e-12;
    return test::run(p, sine(amp, f, rate, t_end));
  };
  const test::Outcome ref = at(6400.0);
  ASSERT_GE(ref.totals.count.contacts, 3);
  std::vector<double> err;
  for (double rate : {100.0, 200.0, 400.0, 800.0}) {
    const test::Outcome o = at(rate);
    EXPECT_EQ(o.totals.count.contacts, ref.totals.count.contacts) << rate;
    err.push_back(std::abs(o.last.x[9] - ref.last.x[9]) + std::abs(o.last.particle_x - ref.last.particle_x));
  }
  for (std::size_t i = 1; i < err.size(); ++i) {
    const double order = std::log2(err[i - 1] / err[i]);
    EXPECT_GT(order, 1.7) << "step " << i << ": errors " << err[i - 1] << " " << err[i];
    EXPECT_LT(order, 2.4) << "step " << i << ": errors " << err[i - 1] << " " << err[i];
  }
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
