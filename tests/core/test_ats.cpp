// The adaptive time series compensator (link/ats.hpp) in closed loop with a
// simulated table whose inverse is known: a pure delay of tau, held command.
// Its backward differences lag by h/2 and h, so the coefficients that invert
// it are a0 = 1, a1 = tau, a2 = tau^2 / 2 + tau h / 2; the fit finds them from
// a wrong start, tracks, respects its bounds and rates, and holds still on a
// table at rest or not measured.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "vines/link/ats.hpp"

namespace vines::link {
namespace {

constexpr double kH = 1e-3;

// A smooth target, like a frame's top floor: two tones, 0.5 and 1.7 Hz.
double target(double t) { return 0.1 * std::sin(2 * M_PI * 0.5 * t) + 0.02 * std::sin(2 * M_PI * 1.7 * t + 0.3); }

// The loop: the table at sample k is the command sent `delay` samples before
// (zero before the start); `each` sees every step's coefficients.
struct Loop {
  int delay;
  std::vector<double> u, xm;
  template <class F>
  void run(Ats* ats, int steps, F each) {
    for (int k = 0; k < steps; ++k) {
      const double m = k >= delay ? u[static_cast<std::size_t>(k - delay)] : 0.0;
      xm.push_back(m);
      u.push_back(ats->step(target(k * kH), m));
      each(k);
    }
  }
};

// A 12 ms pure delay, started from a1 = 0 (no idea of it): after 20 s the
// coefficients are the inverse's, and the table tracks the target within
// 0.02 % of its RMS over the last 5 s (measured: a1 12 us short, a2 within
// 0.04 %, tracking error 0.008 %).
TEST(Ats, LearnsTheInverseOfAPureDelay) {
  const double tau = 0.012;
  Ats ats;
  ats.reset(kH, 1.0, 0.0);
  Loop loop{12, {}, {}};
  loop.run(&ats, 20000, [](int) {});
  EXPECT_NEAR(ats.coefficient(0), 1.0, 1e-4);
  EXPECT_NEAR(ats.coefficient(1), tau, 5e-5);
  EXPECT_NEAR(ats.coefficient(2), tau * tau / 2 + tau * kH / 2, 1e-6);
  double se = 0, sr = 0;
  for (int k = 15000; k < 20000; ++k) {
    const double e = loop.xm[static_cast<std::size_t>(k)] - target(k * kH);
    se += e * e, sr += target(k * kH) * target(k * kH);
  }
  EXPECT_LT(std::sqrt(se / sr), 2e-4);
}

// A 150 ms delay needs a1 beyond its bound (0.1 s): it stops there. At every
// step each coefficient is within its bounds and moved by at most its rate.
TEST(Ats, CoefficientsStayWithinBoundsAndRates) {
  Ats ats;
  ats.reset(kH, 0.5, 0.05);
  double last[3] = {1.0, 0.05, 0.0}, a1_max = 0;
  Loop loop{150, {}, {}};
  loop.run(&ats, 20000, [&](int k) {
    for (int i = 0; i < 3; ++i) {
      const double a = ats.coefficient(i);
      ASSERT_GE(a, kAtsLow[i]) << "k " << k << " a" << i;
      ASSERT_LE(a, kAtsHigh[i]) << "k " << k << " a" << i;
      ASSERT_LE(std::fabs(a - last[i]), kAtsRate[i] * kH * (1 + 1e-12)) << "k " << k << " a" << i;
      last[i] = a;
    }
    a1_max = std::fmax(a1_max, ats.coefficient(1));
  });
  EXPECT_EQ(a1_max, kAtsHigh[1]);  // it went to the bound, not past it
  // A nominal a1 beyond the bound starts at the bound.
  ats.reset(kH, 1.0, 0.3);
  EXPECT_EQ(ats.coefficient(1), kAtsHigh[1]);
}

// At rest (target and table zero) the regularisation keeps the start; a
// table not measured (NaN) leaves the coefficients as they are, and the
// command is then a0 x + a1 x' + a2 x'' of the target alone.
TEST(Ats, HoldsStillAtRestAndWithoutMeasurements) {
  Ats ats;
  ats.reset(kH, 1.0, 0.016);
  for (int k = 0; k < 2000; ++k) EXPECT_EQ(ats.step(0.0, 0.0), 0.0);
  EXPECT_NEAR(ats.coefficient(0), 1.0, 1e-12);
  EXPECT_NEAR(ats.coefficient(1), 0.016, 1e-12);
  EXPECT_NEAR(ats.coefficient(2), 0.0, 1e-12);
  const double a1 = ats.coefficient(1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double u = 0;
  for (int k = 0; k < 3; ++k) u = ats.step(0.001 * (k + 1) * (k + 1), nan);  // x = 1, 4, 9 mm
  EXPECT_EQ(ats.coefficient(1), a1);
  EXPECT_NEAR(u, 0.009 + 0.016 * 0.005 / kH, 1e-9);  // a2 = 0: x + a1 (9 - 4 mm) / h
}

}  // namespace
}  // namespace vines::link
