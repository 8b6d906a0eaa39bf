// Convergence of the fixed-step loop against analytic inputs, on the core
// alone (the loop of vines/step/sim.hpp, no host engine). The linear part is
// discretised exactly for a ground acceleration that is linear between
// samples, so
//  - with a smooth ground motion, the only error is the linear interpolation
//    of the samples: second order in the sensor period, against the analytic
//    solution;
//  - with the VI NES, halving the period keeps that order through contacts.
// (tests/test_convergence.cpp: the same loop on El Centro, through the host.)
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <vector>

#include "loop_runner.hpp"
#include "vines/model/frame.hpp"

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

TEST(Convergence, BareFrameIsSecondOrderForSmoothInput) {
  const double amp = 1.0, f = 1.3, t_end = 8.0;
  const double exact = analytic_top(core_test::paper_scene(DeviceKind::kNone, 200.0), amp, f, t_end);
  std::vector<double> err;
  for (double rate : {25.0, 50.0, 100.0, 200.0}) {
    const core_test::End o =
        core_test::run<NoDevice>(core_test::paper_scene(DeviceKind::kNone, rate), sine(amp, f, rate, t_end));
    err.push_back(std::abs(o.top - exact));
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
    SceneParams p = core_test::paper_scene(DeviceKind::kVines, rate);
    p.device.vines.law = ContactLaw::kKuwabara;
    p.loop.contact_rtol = 1e-12;
    return core_test::run<VinesDevice<ContactLaw::kKuwabara>>(p, sine(amp, f, rate, t_end));
  };
  const core_test::End ref = at(6400.0);
  ASSERT_GE(ref.contacts, 3);
  std::vector<double> err;
  for (double rate : {100.0, 200.0, 400.0, 800.0}) {
    const core_test::End o = at(rate);
    EXPECT_EQ(o.contacts, ref.contacts) << rate;
    err.push_back(std::abs(o.top - ref.top) + std::abs(o.particle - ref.particle));
  }
  for (std::size_t i = 1; i < err.size(); ++i) {
    const double order = std::log2(err[i - 1] / err[i]);
    EXPECT_GT(order, 1.7) << "step " << i << ": errors " << err[i - 1] << " " << err[i];
    EXPECT_LT(order, 2.4) << "step " << i << ": errors " << err[i - 1] << " " << err[i];
  }
}

}  // namespace
