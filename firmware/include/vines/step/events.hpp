// Event location on the sub-steps through a VI NES contact (substep.hpp,
// substep_bounded.hpp): the event functions of each contact mode, an event
// due before any time passes, the first event inside a sub-step bracketed
// on the cubic Hermite interpolant of its event function, and its root
// placed either on the true sub-step (found on the step's dense output, one
// trial step there and a first-order polish, Newton / Illinois on trial
// steps if that misses: substep_through) or on the interpolant (a fixed
// number of Newton steps, substep_bounded). What an event does is the
// contact-mode state machine's (contact_mode.hpp, apply_event in
// substep.hpp).
#pragma once

#include <cmath>
#include <limits>

#include "vines/model/contact_mode.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/dopri5.hpp"
#include "vines/numeric/hermite.hpp"
#include "vines/numeric/inline.hpp"

namespace vines {

// An event due right now, before any time passes: 0 if none, else the wall
// side (-1, +1). Contacts end once the overlap is gone; free particles start
// a contact if they overlap a wall while approaching it; riding particles
// leave the wall once the holding force would pull.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
int due_event(const Model<S, N, Dev>& m, const Stepper& st, const Vec& y) {
  const auto& dm = m.dev;
  const S tol = m.dev.event_tol;
  switch (st.mode) {
    case Mode::kFree: {
      const S r = st.rel_pos(y), rd = st.rel_vel(y);
      // An impact needs an approach speed the law resolves (a particle just
      // released from a wall sits on it with a rounding-level speed).
      const S v_min = Dev::kImpulsive ? static_cast<S>(kStickSpeed) : S(0);
      if (overlap_left<S>(dm, r) > tol && rd < -v_min) return -1;
      if (overlap_right<S>(dm, r) > tol && rd > v_min) return 1;
      return 0;
    }
    case Mode::kContactLeft:
    case Mode::kContactRight: {
      const S q = y(Stepper::kQ), ddl = st.overlap_rate(y);
      const int side = st.mode == Mode::kContactLeft ? -1 : 1;
      return q < S(0) || (q == S(0) && ddl <= S(0)) ? side : 0;
    }
    default: {
      S fp, loss;
      st.force(y, &fp, &loss);
      // Leave once the wall would have to pull (beyond rounding: 1e-9 m/s^2).
      const bool left = st.mode == Mode::kStuckLeft;
      const S pull = (left ? -fp : fp) * m.dev.inv_m;
      return pull > S(1e-9) ? (left ? -1 : 1) : 0;
    }
  }
}

namespace detail {

// Event function of the stepper's mode for the state y (f: its derivative),
// crossing zero upwards at the event; *slope its derivative. side -1, +1:
// the wall (free), or the mode's event (contact: q returns to zero; riding
// a wall: the holding force changes sign); side 0 in a contact: the end of
// the sensor step (t = h).
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
VINES_INLINE S event_value(const Model<S, N, Dev>& m, const Stepper& st, const Vec& y, const Vec& f, int side, S h,
                           S* slope) {
  constexpr int kT = Stepper::kT, kQ = Stepper::kQ;
  const auto& dm = m.dev;
  if (side == 0) {
    *slope = f(kT);
    return y(kT) - h;
  }
  switch (st.mode) {
    case Mode::kFree: {  // overlap with wall `side` exceeds the tolerance
      const S r = st.rel_pos(y), rd = st.rel_vel(y);
      *slope = side < 0 ? -rd : rd;
      return (side < 0 ? overlap_left<S>(dm, r) : overlap_right<S>(dm, r)) - m.dev.event_tol;
    }
    case Mode::kContactLeft:  // q returns to zero
    case Mode::kContactRight:
      *slope = -f(kQ);
      return -y(kQ);
    default: {  // stuck: the holding force changes sign
      S fp, loss;
      st.force(y, &fp, &loss);
      *slope = S(0);
      return st.mode == Mode::kStuckLeft ? -fp : fp;
    }
  }
}

// Does an event happen inside the sub-step from (y0, f0) to (y1, f1), of
// length du? Which first? From the cubic Hermite interpolant of each event
// function (linear for the holding force, whose slope is not known): true
// and *theta (the fraction of the sub-step: the first up-crossing on the
// cubic, bisected `halvings` times after a 16-point grid), *side; false if
// none.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
VINES_INLINE bool first_event(const Model<S, N, Dev>& m, const Stepper& st, const Vec& y0, const Vec& f0,
                              const Vec& y1, const Vec& f1, S du, S h, int halvings, S* theta, int* side) {
  const bool reg = st.regular();
  bool any = false;
  for (int sd = -1; sd <= 1; ++sd) {
    if (sd == 0 && !reg) continue;           // t = h: only in w
    if (st.mode != Mode::kFree && sd == 1) break;
    S s0, s1;
    const S g0 = event_value(m, st, y0, f0, sd, h, &s0), g1 = event_value(m, st, y1, f1, sd, h, &s1);
    const auto cub = numeric::Cubic<S>::make(g0, s0, g1, s1, du);
    const bool stuck = riding(st.mode);
    const bool hit = g1 > S(0) || (!stuck && g0 <= S(0) && cub.max_value() > S(0));
    if (!hit || g0 > S(0)) continue;
    const S th = stuck ? g0 / (g0 - g1) : cub.first_upcrossing(halvings);
    if (!any || th < *theta) {
      *theta = th;
      *side = sd;
      any = true;
    }
  }
  return any;
}

// The change of an event function along a direction v of the state (the
// event functions of the walls, of q and of t are affine in the state).
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
VINES_INLINE S event_change(const Model<S, N, Dev>& m, const Stepper& st, const Vec& v, int side) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  if (side == 0) return v(Stepper::kT);
  if (in_contact(st.mode)) return -v(Stepper::kQ);
  const S dr = v(NX) - m.dev_x(v.template head<NX>());
  return side < 0 ? -dr : dr;
}

// kIterations Newton steps on the curve c (value(theta), slope(theta): a
// cubic interpolant, a DenseEvent) from theta, kept inside [lo, hi] where c
// rises through zero (bisection where Newton would leave it): an event
// placed on a sub-step's interpolant, with a fixed worst case.
template <int kIterations, typename Curve, typename S>
S polish_root(const Curve& c, S theta, S lo, S hi) {
  for (int it = 0; it < kIterations; ++it) {
    const S v = c.value(theta);
    if (v > S(0)) hi = theta;
    else lo = theta;
    const S slope = c.slope(theta);
    S next = slope > S(0) ? theta - v / slope : S(0.5) * (lo + hi);
    if (!(next >= lo && next <= hi)) next = S(0.5) * (lo + hi);
    if (next == theta) break;
    theta = next;
  }
  return theta;
}

// An event function less its target along a step's dense output: the
// dense output of the step projected on it (an affine function of the
// dense output is the dense output of its values), a quintic in theta.
template <typename S>
struct DenseEvent {
  numeric::Dopri5Dense<S> d;

  S value(S th) const { return d.at(th); }
  S slope(S th) const {  // d/dtheta
    const S th1 = S(1) - th;
    const S a = d.c3 + th1 * d.c4, b = d.c2 + th * a;
    return d.c1 + th1 * b + th * (th1 * (a - th * d.c4) - b);
  }

  // The first theta in (0, 1] where it rises through zero (value(0) <= 0):
  // a 16-point grid (numeric::grid_upcrossing), then Newton steps inside the
  // bracket to rounding (polish_root). False if the grid finds no crossing.
  bool first_crossing(S* theta) const {
    S lo, hi;
    if (!numeric::grid_upcrossing(*this, d.y0, &lo, &hi)) return false;
    *theta = polish_root<60>(*this, S(0.5) * (lo + hi), lo, hi);
    return true;
  }
};

// The event function of `side` less its target (g0 at y, g1 at r.y) along
// the dense output of the step r from (y, f) of length du (not for a
// particle riding a wall: its holding force is not affine in the state).
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
DenseEvent<S> dense_event(const Model<S, N, Dev>& m, const Stepper& st, const Vec& f,
                          const numeric::Dopri5Result<Vec>& r, S du, int side, S g0, S g1) {
  numeric::Dopri5Result<S> p;
  p.y = g1;
  p.f = event_change(m, st, r.f, side);
  p.k3 = event_change(m, st, r.k3, side);
  p.k4 = event_change(m, st, r.k4, side);
  p.k5 = event_change(m, st, r.k5, side);
  p.k6 = event_change(m, st, r.k6, side);
  return {numeric::dopri5_dense(p, g0, event_change(m, st, f, side), du)};
}

// Places the event first_event found (side; theta its guess) on the true
// sub-step r from (y, f) at u, of length du. The acceptance band of the
// event function is [0, tol] (the end of the sensor step, side 0: t within
// rounding of h), aimed at its middle:
//   1. the root on the step's dense output (DenseEvent);
//   2. one trial step to it;
//   3. its end moved onto the root by a first-order step along f (length
//      dtau = -g / g'), which errs by dtau^2 y'' / 2: taken only while
//      |dtau| <= 0.1 sqrt(rtol) du, where that is below 0.005 rtol of the
//      step's own curvature term; the dense output's error keeps dtau far
//      smaller.
// Where a step misses (no dense crossing, a riding particle, dtau too long,
// still outside the band), Newton steps on trial steps (their slope comes
// with each), Illinois steps where Newton would leave the bracket; at most
// 40. Returns the step to the event, *tau_out its length.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
VINES_INLINE numeric::Dopri5Result<Vec> locate_event(const Model<S, N, Dev>& m, const Stepper& st, S u, const Vec& y,
                                                     const Vec& f, const numeric::Dopri5Result<Vec>& r, S du, S h,
                                                     S theta, int side, S rtol, S* tau_out) {
  constexpr S kEps = std::numeric_limits<S>::epsilon();
  const S tol = side == 0 ? S(4) * kEps * h : m.dev.event_tol;
  auto in_band = [&](S g) { return std::fabs(g) <= tol && g >= S(0); };
  S lo = S(0), hi = du, slope;
  S glo = event_value(m, st, y, f, side, h, &slope);
  S ghi = event_value(m, st, r.y, r.f, side, h, &slope);
  const S aim = S(0.5) * tol;
  S th;
  if (!riding(st.mode) && dense_event(m, st, f, r, du, side, glo - aim, ghi - aim).first_crossing(&th)) theta = th;
  if (!(ghi > S(0))) ghi = S(1);
  S tau = theta * du;
  auto rr = numeric::dopri5_step<Vec>(st, u, y, f, tau);
  S g = event_value(m, st, rr.y, rr.f, side, h, &slope);
  if (!in_band(g) && slope > S(0)) {
    const S dtau = -(g - aim) / slope;
    if (std::fabs(dtau) <= S(0.1) * std::sqrt(rtol) * du && tau + dtau > S(0) && tau + dtau < du) {
      tau += dtau;
      rr.y += dtau * rr.f;
      rr.f = st(u + tau, rr.y);
      g = event_value(m, st, rr.y, rr.f, side, h, &slope);
    }
  }
  int last = 0;
  for (int it = 0; it < 40 && !in_band(g); ++it) {
    if (g > S(0)) { hi = tau; ghi = g; if (last == 1) glo *= S(0.5); last = 1; }
    else { lo = tau; glo = g; if (last == -1) ghi *= S(0.5); last = -1; }
    if (hi - lo <= S(4) * kEps * (std::fabs(u) + hi)) {
      tau = hi;
    } else {
      tau = slope > S(0) ? tau - (g - aim) / slope : lo;
      if (!(tau > lo && tau < hi))
        tau = (ghi > S(0) && glo < S(0)) ? (lo * ghi - hi * glo) / (ghi - glo) : S(0.5) * (lo + hi);
      if (!(tau > lo && tau < hi)) tau = S(0.5) * (lo + hi);
    }
    rr = numeric::dopri5_step<Vec>(st, u, y, f, tau);
    if (tau == hi && hi - lo <= S(4) * kEps * (std::fabs(u) + hi)) break;
    g = event_value(m, st, rr.y, rr.f, side, h, &slope);
  }
  *tau_out = tau;
  return rr;
}

}  // namespace detail

}  // namespace vines
