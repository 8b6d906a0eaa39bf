// A sphere hitting a fixed rigid wall (paper Fig. 2): the reference problem
// behind the contact laws. Integrated in double with adaptive Dormand-Prince
// steps (the sub-steppers' step-size control, step_control.hpp) and the
// contact end located to rounding; used to calibrate the
// Kuwabara relaxation time tau from (eps, v_ref) and by the tests.
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "vines/model/contact.hpp"
#include "vines/numeric/dopri5.hpp"
#include "vines/numeric/hermite.hpp"
#include "vines/numeric/step_control.hpp"

namespace vines {

struct BounceResult {
  double restitution = 0.0;  // rebound speed / impact speed
  double duration = 0.0;     // contact duration [s]
  double max_overlap = 0.0;  // [m]
  double dissipated = 0.0;   // energy lost in the rate term [J]
  int steps = 0;
  bool ok = false;           // false: the step budget ran out
};

// Mass m [kg] hits the wall at speed v > 0 [m/s] under `law`.
template <typename Law>
BounceResult bounce(const Law& law, double m, double v, double rtol = 1e-13) {
  using Vec = Eigen::Vector3d;  // overlap, overlap rate, dissipated energy
  const double c = law.c;
  const double d_scale = contact::hertz_max_overlap(m, c, v);
  const double t_scale = contact::hertz_duration(m, c, v);
  auto rhs = [&](double, const Vec& y) {
    Vec d;
    const double dl = y(0) > 0.0 ? y(0) : 0.0;
    const contact::Force<double> f = law(dl, y(1));
    d << y(1), -f.total() / m, f.dissipative * y(1);
    return d;
  };
  auto err_norm = [&](const Vec& e, const Vec& y0, const Vec& y1) {
    const double e0 = std::fabs(e(0)) / (rtol * (d_scale + std::fmax(std::fabs(y0(0)), std::fabs(y1(0)))));
    const double e1 = std::fabs(e(1)) / (rtol * (v + std::fmax(std::fabs(y0(1)), std::fabs(y1(1)))));
    return std::fmax(e0, e1);
  };

  BounceResult out;
  Vec y(0.0, v, 0.0);
  Vec f = rhs(0.0, y);
  double t = 0.0, h = 1e-3 * t_scale;
  constexpr int kMaxSteps = 200000;
  while (out.steps < kMaxSteps) {
    const auto r = numeric::dopri5_step<Vec>(rhs, t, y, f, h);
    const double en = err_norm(r.err, y, r.y);
    if (en > 1.0) {
      h *= numeric::shrink_factor(en);
      continue;
    }
    ++out.steps;
    if (r.y(0) < 0.0 && r.y(1) < 0.0) {
      // The sphere left the wall inside this step: place the instant where the
      // overlap returns to zero (cubic guess, then Newton on the true step).
      const auto cub = numeric::Cubic<double>::make(-y(0), -y(1), -r.y(0), -r.y(1), h);
      double th = cub.first_upcrossing();
      auto rr = numeric::dopri5_step<Vec>(rhs, t, y, f, th * h);
      for (int it = 0; it < 20 && std::fabs(rr.y(0)) > 1e-15 * d_scale; ++it) {
        th -= rr.y(0) / (rr.y(1) * h);
        rr = numeric::dopri5_step<Vec>(rhs, t, y, f, th * h);
      }
      out.duration = t + th * h;
      out.restitution = -rr.y(1) / v;
      out.dissipated = rr.y(2);
      out.ok = true;
      return out;
    }
    // Deepest overlap: inside the step where the overlap rate changes sign.
    if (y(1) >= 0.0 && r.y(1) <= 0.0) {
      const double top = numeric::Cubic<double>::make(y(0), y(1), r.y(0), r.y(1), h).max_value();
      if (top > out.max_overlap) out.max_overlap = top;
    }
    t += h;
    y = r.y;
    f = r.f;
    h *= numeric::grow_factor(en);
  }
  return out;
}

// Kuwabara relaxation time tau such that a mass m hitting the wall at v_ref
// rebounds with restitution eps (0 < eps < 1); eps = 1 gives tau = 0.
// Bisection-secant (Illinois) on log tau to ~1e-12 relative.
inline double calibrate_kuwabara_tau(double c, double m, double eps, double v_ref) {
  if (eps >= 1.0) return 0.0;
  auto resid = [&](double tau) {
    return bounce(contact::Kuwabara<double>{c, 1.5 * c * tau}, m, v_ref).restitution - eps;
  };
  // tau ~ t_c D(eps) is the right order; widen until eps is bracketed.
  const double tc = contact::hertz_duration(m, c, v_ref);
  double lo = 1e-3 * tc * contact::tsuji_d(eps), hi = lo;
  double flo = resid(lo), fhi = flo;
  while (flo < 0.0 && lo > 1e-12 * tc) { lo *= 0.1; flo = resid(lo); }
  while (fhi > 0.0 && hi < 1e3 * tc) { hi *= 10.0; fhi = resid(hi); }
  if (flo < 0.0 || fhi > 0.0) return -1.0;  // not bracketed: caller reports
  double x0 = std::log(lo), x1 = std::log(hi);
  int side = 0;
  for (int it = 0; it < 200 && std::fabs(x1 - x0) > 1e-13; ++it) {
    const double x = (x0 * fhi - x1 * flo) / (fhi - flo);
    const double fx = resid(std::exp(x));
    if (fx == 0.0) return std::exp(x);
    if ((fx > 0.0) == (flo > 0.0)) {
      x0 = x; flo = fx;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      x1 = x; fhi = fx;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
  }
  return std::exp(0.5 * (x0 + x1));
}

}  // namespace vines
