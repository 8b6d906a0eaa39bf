// The split contact step (vines/split/forced_contact.hpp) on a 2-DOF
// problem: the paper's sphere (55.8 t, Kuwabara, eps 0.7 at 0.5 m/s) hits
// the wall of a 98 t floor on a spring to the ground (5 Hz, 2 % damping)
// that is already moving. The split: per 1 ms sensor step, the overlap's
// scalar equation with the floor's free acceleration as a Taylor cubic, then
// the floor's exact free step plus its response to the force's moments and
// the particle's free flight minus the impulse terms. Against the two
// bodies integrated together (classic Runge-Kutta, 4 ns steps).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <Eigen/Core>

#include "vines/fixed/contact_coupling.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/devices.hpp"
#include "vines/numeric/expm.hpp"
#include "vines/numeric/fixed.hpp"
#include "vines/split/contact_step.hpp"
#include "vines/split/forced_contact.hpp"

namespace {

using namespace vines;
using Kernel = contact::Kuwabara<double>;
constexpr double kPi = 3.14159265358979323846;
constexpr double kFloorMass = 98000.0, kOmega = 2.0 * kPi * 5.0, kZeta = 0.02;
constexpr double kH = 1e-3;

struct TwoBodies {
  Kernel law;
  double m, mf, k, c;
};

TwoBodies two_bodies() {
  VinesParams p;
  p.law = ContactLaw::kKuwabara;
  const VinesDesign d = design_vines(p, 0.05 * 1115.9e3, kFloorMass);
  return {{d.c, d.g}, d.mass, kFloorMass, kFloorMass * kOmega * kOmega, 2.0 * kZeta * kOmega * kFloorMass};
}

struct Outcome {
  double duration = 0, rebound = 0, impulse = 0;  // contact
  double x = 0, v = 0, s = 0, sv = 0;             // floor and particle at the end of the step the contact ends in
};

// Both bodies together: particle s, floor x (wall at s = x), from first touch
// at t = 0 with approach speed v0; the floor at x0, v0f.
Outcome together(const TwoBodies& su, double v0, double x0, double vf0) {
  using V = Eigen::Matrix<double, 5, 1>;  // s, s', x, x', impulse
  auto rate = [&](const V& y) {
    const double d = y(0) - y(2), dd = y(1) - y(3);
    const double f = d > 0.0 ? su.law(d, dd).total() : 0.0;
    V r;
    r << y(1), -f / su.m, y(3), (f - su.c * y(3) - su.k * y(2)) / su.mf, f;
    return r;
  };
  V y;
  y << x0, vf0 + v0, x0, vf0, 0.0;
  constexpr int kPerStep = 250000;  // 4 ns
  const double dt = kH / kPerStep;
  Outcome o;
  bool ended = false;
  for (int step = 0; step < 50 && !ended; ++step) {
    for (int i = 0; i < kPerStep; ++i) {
      const V next = numeric::rk4_step(rate, y, dt);
      if (!ended && next(0) - next(2) < 0.0) {
        const double d0 = y(0) - y(2), d1 = next(0) - next(2), th = d0 / (d0 - d1);
        o.duration = (step * kPerStep + i + th) * dt;
        o.rebound = -((y(1) - y(3)) + th * ((next(1) - next(3)) - (y(1) - y(3)))) / v0;
        o.impulse = y(4) + th * (next(4) - y(4));
        ended = true;
      }
      y = next;
    }
  }
  o.s = y(0);
  o.sv = y(1);
  o.x = y(2);
  o.v = y(3);
  return o;
}

// What one sensor step's contact integration gives back, in SI.
struct ContactPart {
  fixed::ContactState<double> y;
  bool ended = false;
};

// The split, step by step: the overlap's equation by `integrate(c, q, u)`
// (the coupling c with the floor's free acceleration set, the contact's q
// and u at the step's start), then the floor's exact step plus the force's
// moments, the particle's free flight less the impulse terms. A step's
// integration reaches its end within t_tol of it unless the contact ended.
template <typename Integrate>
Outcome split_with(const TwoBodies& su, double v0, double x0, double vf0, double t_tol, Integrate&& integrate) {
  using M2 = Eigen::Matrix2d;
  M2 a;
  a << 0.0, 1.0, -su.k / su.mf, -su.c / su.mf;
  const M2 phi = numeric::expm<M2>(a * kH);
  Eigen::Vector2d akb[5];
  akb[0] << 0.0, 1.0 / su.mf;
  for (int k = 1; k < 5; ++k) akb[k] = a * akb[k - 1];
  fixed::ContactCoupling<double> c;
  c.inv_m_star = 1.0 / su.m + 1.0 / su.mf;
  for (int k = 1; k < 5; ++k) c.markov[k - 1] = akb[k](1);  // M_2 .. M_5
  c.h = kH;
  Eigen::Vector2d floor(x0, vf0);
  double s = x0, sv = vf0 + v0, q = 0.0, u = v0;
  Outcome o;
  for (int step = 0; step < 50; ++step) {
    // g(t) = -x''(t) of the free floor: its derivatives at the step's start.
    double x[6] = {floor(0), floor(1)};
    for (int k = 2; k < 6; ++k) x[k] = -(su.c * x[k - 1] + su.k * x[k - 2]) / su.mf;
    const double factorial[4] = {1, 1, 2, 6};  // c.g in powers of t
    for (int k = 0; k < 4; ++k) c.g[k] = -x[k + 2] / factorial[k];
    const ContactPart r = integrate(c, q, u);
    EXPECT_TRUE(r.ended || r.y(2) >= kH * (1 - t_tol)) << "step " << step;
    const double mu[4] = {r.y(3), r.y(4), r.y(5), r.y(6)};
    Eigen::Vector2d next = phi * floor;
    for (int k = 0; k < 4; ++k) next += akb[k] * mu[k];
    s += sv * kH - mu[1] / su.m;
    sv -= mu[0] / su.m;
    floor = next;
    o.impulse += mu[0];
    if (r.ended) {
      o.duration = step * kH + r.y(2);
      o.rebound = -r.y(1) / v0;
      break;
    }
    // Still in contact: q back on the assembled overlap, u its rate.
    q = std::sqrt(std::sqrt(std::fmax(s - floor(0), 0.0)));
    u = sv - floor(1);
  }
  o.s = s;
  o.sv = sv;
  o.x = floor(0);
  o.v = floor(1);
  return o;
}

// In SI, steps of dw.
Outcome split(const TwoBodies& su, double v0, double x0, double vf0, double dw) {
  return split_with(su, v0, x0, vf0, 1e-12, [&](const fixed::ContactCoupling<double>& c, double q, double u) {
    fixed::ContactState<double> y0 = fixed::ContactState<double>::Zero();
    y0(0) = q;
    y0(1) = u;
    const fixed::ForcedContact<double> r = fixed::forced_contact(su.law, c, y0, dw, 0.0, 100000);
    return ContactPart{r.y, r.ended};
  });
}

// The overlap's equation in the contact's units (fixed/contact_coupling.hpp:
// V bounds the impact speed, the moments' arm in units of the sensor step)
// and the scalar S, stepped by the loop's rule (split/contact_step.hpp, n
// steps an impact, dw at most 1); *steps counts its Runge-Kutta steps.
template <typename S>
Outcome split_in_units(const TwoBodies& su, double v0, double x0, double vf0, int n, int* steps) {
  const fixed::CouplingUnits cu{fixed::contact_units(su.m, su.law.c, 2.0 * v0), kH};
  const auto law = fixed::scaled_kernel<S>(su.law, cu.u);
  const double inv_m_star = (1.0 / su.m + 1.0 / su.mf) * su.m, law_c = static_cast<double>(law.c);
  const S m_star_c(1.0 / (inv_m_star * law_c)), dw_unit(1.0 / (n * std::sqrt(0.8 * law_c * inv_m_star)));
  *steps = 0;
  // Q3.28 places the step's end to its resolution in units of T (2.6 ms).
  return split_with(su, v0, x0, vf0, 1e-7, [&](const fixed::ContactCoupling<double>& c_si, double q, double u) {
    const fixed::ContactCoupling<S> c = fixed::scaled_coupling<S>(c_si, cu);
    fixed::ContactState<double> y_si = fixed::ContactState<double>::Zero();
    y_si(0) = q;
    y_si(1) = u;
    const fixed::ContactState<double> y0_units = fixed::convert_state(y_si, cu, true);
    const fixed::ContactState<S> y0 = y0_units.template cast<S>();
    const fixed::ContactStep<S> rule =
        fixed::contact_step(y0(0), y0(1), fixed::g_bound(c), m_star_c, S(0.01), dw_unit, S(1));
    const fixed::ForcedContact<S> r = fixed::forced_contact(law, c, y0, rule.dw, rule.q_e, 4096);
    EXPECT_FALSE(r.capped);
    *steps += r.steps;
    fixed::ContactState<double> y_back;
    for (int i = 0; i < y_back.size(); ++i) y_back(i) = static_cast<double>(r.y(i));
    return ContactPart{fixed::convert_state(y_back, cu, false), r.ended};
  });
}

TEST(ForcedContact, SplitStepMatchesTheTwoBodies) {
  const TwoBodies su = two_bodies();
  for (double vf0 : {-0.3, 0.0, 0.3}) {
    const Outcome ref = together(su, 0.5, 0.05, vf0);
    const Outcome got = split(su, 0.5, 0.05, vf0, 1.0 / 256);
    std::printf("floor at 0.05 m, %+.1f m/s: duration %.6f ms (together %.6f), rebound %.7f (%.7f), impulse "
                "%.3f (%.3f) N s, floor %.9f m (%.9f), particle %.9f m (%.9f)\n",
                vf0, got.duration * 1e3, ref.duration * 1e3, got.rebound, ref.rebound, got.impulse, ref.impulse,
                got.x, ref.x, got.s, ref.s);
    // Measured: 1e-7, 1e-7, 5e-8 relative; positions within 1e-9 m.
    EXPECT_NEAR(got.duration / ref.duration, 1.0, 1e-6);
    EXPECT_NEAR(got.rebound, ref.rebound, 1e-6);
    EXPECT_NEAR(got.impulse / ref.impulse, 1.0, 1e-6);
    EXPECT_NEAR(got.x, ref.x, 1e-8);
    EXPECT_NEAR(got.s, ref.s, 1e-8);
  }
}

}  // namespace

// In the contact's units, double and Q3.28 run the same overlap equation
// step for step: the fixed-point one against the two bodies integrated
// together, and against the same split in double (the difference is then
// Q3.28's rounding alone), with no saturation.
TEST(ForcedContact, SplitStepInFixedPointMatchesTheTwoBodies) {
  using Q = numeric::Fixed<28>;
  const TwoBodies su = two_bodies();
  numeric::fixed_saturations() = 0;
  for (double vf0 : {-0.3, 0.0, 0.3}) {
    const Outcome ref = together(su, 0.5, 0.05, vf0);
    int steps_d = 0, steps_q = 0;
    const Outcome d = split_in_units<double>(su, 0.5, 0.05, vf0, 64, &steps_d);
    const Outcome q = split_in_units<Q>(su, 0.5, 0.05, vf0, 64, &steps_q);
    std::printf("floor %+.1f m/s, 64 steps: duration %.7f ms (double %.7f, together %.7f), rebound %.8f (%.8f, "
                "%.8f), impulse %.4f (%.4f, %.4f) N s, floor %.3e m from together (double %.3e), %d Runge-Kutta "
                "steps (%d)\n",
                vf0, q.duration * 1e3, d.duration * 1e3, ref.duration * 1e3, q.rebound, d.rebound, ref.rebound,
                q.impulse, d.impulse, ref.impulse, q.x - ref.x, d.x - ref.x, steps_q, steps_d);
    // Measured: within 2e-7 of together, 3e-8 of double; 138-144 steps each.
    EXPECT_NEAR(q.duration / ref.duration, 1.0, 1e-6);
    EXPECT_NEAR(q.rebound, ref.rebound, 1e-6);
    EXPECT_NEAR(q.impulse / ref.impulse, 1.0, 1e-6);
    EXPECT_NEAR(q.x, ref.x, 1e-9);
    EXPECT_NEAR(q.s, ref.s, 1e-9);
    EXPECT_NEAR(q.duration / d.duration, 1.0, 1e-7);
    EXPECT_NEAR(q.rebound, d.rebound, 1e-7);
  }
  EXPECT_EQ(numeric::fixed_saturations(), 0u);
}
