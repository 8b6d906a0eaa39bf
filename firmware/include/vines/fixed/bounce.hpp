// The paper's Fig. 2 problem (bounce.hpp: a mass hitting a fixed rigid wall)
// in fixed point, in the units of a contact (fixed/contact.hpp) and in the
// regularised variable w of the loop's contacts (dt/dw = 4 q^3, so that
// dq/dw = dd and nothing is singular at first touch):
//   q' = u,  u' = -4 q^3 F^(q, u),  tau' = 4 q^3,  e' = 4 q^3 F^_diss(q, u) u
// (q^ = q / D^{1/4}, u = dd / V, tau = t / T, e the energy lost in m V^2).
// V must bound the impact speed: at u0 = 1 the largest rate, 4 q^3 F^, is
// 5 (q^ 1, F^ 5/4), within Q3.28's 8; at u0 = 2 it would be 17.
// Classic Runge-Kutta (numeric/rk4.hpp), `steps` steps a unit of w; the
// contact ends where q returns to zero, placed by Newton steps on a re-taken
// last step. Bounded
// work: a contact spans w of about 2.3 at V (q^ rises to 1 and back at a
// rate u <= 1), more for slower impacts, so the loop stops after 16 units of
// w whatever the law does. Every operation is Fixed's: the same bits on
// every core.
#pragma once

#include <Eigen/Core>

#include "vines/fixed/contact.hpp"
#include "vines/numeric/fixed.hpp"
#include "vines/numeric/rk4.hpp"

namespace vines::fixed {

template <typename S>
struct FixedBounce {
  S restitution = S(0), duration = S(0), max_q = S(0), dissipated = S(0);  // in the contact's units
  int steps = 0;
  bool ok = false;  // false: no rebound within the bounded work
};

namespace detail {

// [q, u, tau, e] and its rate in w.
template <typename S>
using BounceState = Eigen::Matrix<S, 4, 1>;

template <typename S, typename K>
BounceState<S> bounce_rate(const K& k, const BounceState<S>& y) {
  const S q = y(0), u = y(1), j = S(4) * q * q * q;  // dt/dw
  const contact::Force<S> f = k.regular(q, u);
  BounceState<S> d;
  d << u, -(j * f.total()), j, j * f.dissipative * u;
  return d;
}

}  // namespace detail

// The impact at speed u0 (in units of V) of the kernel k (scaled_kernel).
template <typename S, typename K>
FixedBounce<S> bounce_fixed(const K& k, S u0, int steps_per_unit = 64) {
  const S h = S(1.0 / steps_per_unit);  // a Q3.28 holds 1 / 64, not 64
  auto rate = [&k](const detail::BounceState<S>& y) { return detail::bounce_rate(k, y); };
  auto rk4 = [&](const detail::BounceState<S>& y, S dw) { return numeric::rk4_step(rate, y, dw); };
  detail::BounceState<S> y;
  y << S(0), u0, S(0), S(0);
  FixedBounce<S> out;
  const int max_steps = 16 * steps_per_unit;
  for (; out.steps < max_steps; ++out.steps) {
    const detail::BounceState<S> next = rk4(y, h);
    if (next(0) < S(0)) {
      // Back at zero overlap inside this step: theta from the secant, then
      // Newton on the re-taken step (q' = u there).
      S theta = y(0) / (y(0) - next(0));
      detail::BounceState<S> end = rk4(y, theta * h);
      for (int it = 0; it < 3 && end(1) < S(0); ++it) {
        theta = theta - end(0) / (end(1) * h);
        end = rk4(y, theta * h);
      }
      out.restitution = -end(1) / u0;
      out.duration = end(2);
      out.dissipated = end(3);
      out.ok = true;
      return out;
    }
    y = next;
    if (y(0) > out.max_q) out.max_q = y(0);
  }
  return out;
}

}  // namespace vines::fixed
