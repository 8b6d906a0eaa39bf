// The paper's Fig. 2 problem (bounce.hpp: a mass hitting a fixed rigid wall)
// in fixed point, in the units of a contact (fixed/contact.hpp) and in the
// regularised variable w of the loop's contacts (dt/dw = 4 q^3, so that
// dq/dw = dd and nothing is singular at first touch):
//   q' = u,  u' = -4 q^3 F^(q, u),  tau' = 4 q^3,  e' = 4 q^3 F^_diss(q, u) u
// (q^ = q / D^{1/4}, u = dd / V, tau = t / T, e the energy lost in m V^2).
// V must bound the impact speed: at u0 = 1 the largest rate, 4 q^3 F^, is
// 5 (q^ 1, F^ 5/4), within Q3.28's 8; at u0 = 2 it would be 17.
// Classic Runge-Kutta, `steps` steps a unit of w; the contact ends where q
// returns to zero, placed by Newton steps on a re-taken last step. Bounded
// work: a contact spans w of about 2.3 at V (q^ rises to 1 and back at a
// rate u <= 1), more for slower impacts, so the loop stops after 16 units of
// w whatever the law does. Every operation is Fixed's: the same bits on
// every core.
#pragma once

#include "vines/fixed/contact.hpp"
#include "vines/numeric/fixed.hpp"

namespace vines::fixed {

template <typename S>
struct FixedBounce {
  S restitution = S(0), duration = S(0), max_q = S(0), dissipated = S(0);  // in the contact's units
  int steps = 0;
  bool ok = false;  // false: no rebound within the bounded work
};

namespace detail {

template <typename S>
struct BounceState {
  S q, u, tau, e;
};

template <typename S, typename K>
BounceState<S> bounce_rate(const K& k, const BounceState<S>& y) {
  const S q2 = y.q * y.q, j = S(4) * q2 * y.q;  // dt/dw
  const contact::Force<S> f = k.regular(y.q, y.u);
  return {y.u, -(j * f.total()), j, j * f.dissipative * y.u};
}

template <typename S>
BounceState<S> axpy(const BounceState<S>& y, S h, const BounceState<S>& d) {
  return {y.q + h * d.q, y.u + h * d.u, y.tau + h * d.tau, y.e + h * d.e};
}

template <typename S, typename K>
BounceState<S> rk4(const K& k, const BounceState<S>& y, S h) {
  const S half = h / S(2);
  const BounceState<S> k1 = bounce_rate(k, y);
  const BounceState<S> k2 = bounce_rate(k, axpy(y, half, k1));
  const BounceState<S> k3 = bounce_rate(k, axpy(y, half, k2));
  const BounceState<S> k4 = bounce_rate(k, axpy(y, h, k3));
  // Each rate times its weight before any sum: two rates of 5 would overflow
  // Q3.28's 8, their weighted increments are far below it.
  const S sixth = h / S(6), third = h / S(3);
  auto inc = [&](S a, S b, S c, S d) { return sixth * a + third * b + third * c + sixth * d; };
  return {y.q + inc(k1.q, k2.q, k3.q, k4.q), y.u + inc(k1.u, k2.u, k3.u, k4.u),
          y.tau + inc(k1.tau, k2.tau, k3.tau, k4.tau), y.e + inc(k1.e, k2.e, k3.e, k4.e)};
}

}  // namespace detail

// The impact at speed u0 (in units of V) of the kernel k (scaled_kernel).
template <typename S, typename K>
FixedBounce<S> bounce_fixed(const K& k, S u0, int steps_per_unit = 64) {
  const S h = S(1.0 / steps_per_unit);  // a Q3.28 holds 1 / 64, not 64
  detail::BounceState<S> y{S(0), u0, S(0), S(0)};
  FixedBounce<S> out;
  const int max_steps = 16 * steps_per_unit;
  for (; out.steps < max_steps; ++out.steps) {
    const detail::BounceState<S> next = detail::rk4(k, y, h);
    if (next.q < S(0)) {
      // Back at zero overlap inside this step: theta from the secant, then
      // Newton on the re-taken step (q' = u there).
      S theta = y.q / (y.q - next.q);
      detail::BounceState<S> end = detail::rk4(k, y, theta * h);
      for (int it = 0; it < 3 && end.u < S(0); ++it) {
        theta = theta - end.q / (end.u * h);
        end = detail::rk4(k, y, theta * h);
      }
      out.restitution = -end.u / u0;
      out.duration = end.tau;
      out.dissipated = end.e;
      out.ok = true;
      return out;
    }
    y = next;
    if (y.q > out.max_q) out.max_q = y.q;
  }
  return out;
}

}  // namespace vines::fixed
