// The bounded contact scheme (loop.contact_scheme = "bounded"): a sensor step
// in which the VI NES particle may touch a wall costs at most
//   K = loop.bounded_substeps Dormand-Prince sub-steps (no rejections),
//   kBoundedEvents events, each placed without trial steps,
// whatever happens in the step: its worst case is fixed by construction. It
// integrates the same equations as substep_through (substep.hpp), with the
// same right-hand side (contacts in the regularised variable w, dt/dw =
// 4 q^3), event functions, event actions and bookkeeping; what differs is
// how sub-steps are sized and events placed:
//   - Each sub-step is aimed: its length is what remains to the next
//     predicted event (a contact start, a contact end, the sensor step's end
//     inside a contact), split evenly over the sub-steps left for it, the last
//     one aimed kAimMargin past the event. Predictions come from cheap local
//     models of the event function (its Taylor cubic in free flight; in a
//     contact q(w) = q0 + d' w + (dd'/dw) w^2 / 2 and t(w) = integral of
//     4 q^3): a few scalar Newton steps each.
//   - Outside a contact a segment takes one sub-step (at sensor rates the
//     free frame and particle are smooth over a step); a contact gets every
//     sub-step left but one per event predicted after it.
//   - An event inside a sub-step is placed on the cubic Hermite interpolant
//     of its event function over the sub-step (at most kBoundedRootIterations
//     Newton steps), and the state there is the cubic Hermite interpolant of
//     the sub-step's state: no trial steps. As the sub-step was aimed at the
//     event, it lies near the sub-step's end, where the interpolant is
//     closest to the solution (its error vanishes like theta^2 (1 - theta)^2).
//   - A sub-step in a contact never spans more than kStableStep radians of
//     the contact's own oscillation in w (estimated from q and dd'/dw), so
//     that a budget too small for the sensor rate degrades the answer but
//     cannot blow the contact up.
//   - What the budget cannot pay for is not done in this step, and counted
//     (count.cap_hits): a contact start or impact found in a sub-step with no
//     sub-step left after it waits for the next step (due_event applies it
//     then); a contact that ends in the last sub-step is followed to the
//     step's end by one Euler step of the free flight; a contact whose last
//     sub-step falls short of the step's end is extrapolated to it on the
//     interpolant (up to kMaxExtrapolation of a sub-step), else the step ends
//     where it stands (the contact lasts that much longer). None of this
//     happens on El Centro at 1 kHz or 2048 Hz with the default budget.
//   - Per-floor peaks (loop.floor_peaks) are taken once a step from its two
//     ends; the top floor's peak sub-step by sub-step, as substep_through.
// Work of a step, at most: K sub-steps (6 right-hand sides each, first same
// as last, no error estimate), one right-hand side per event and per q
// re-sync (at most one a sub-step), kBoundedEvents interpolations, and per
// sub-step a prediction (a few dozen scalar operations, at most
// kBoundedPredictIterations Newton steps) and the top-floor bookkeeping.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/dopri5.hpp"
#include "vines/numeric/hermite.hpp"
#include "vines/numeric/minmax.hpp"
#include "vines/step/events.hpp"
#include "vines/step/substep_common.hpp"

namespace vines {

// Most events (contact starts and ends, impacts, leaving a wall) applied in
// one sensor step. A contact start (or impact) needs two free slots, so that
// the end of any contact always finds one.
inline constexpr int kBoundedEvents = 4;

namespace detail {

// Newton steps that place an event on a sub-step's interpolant, and that
// solve a prediction.
inline constexpr int kBoundedRootIterations = 4;
inline constexpr int kBoundedPredictIterations = 8;
// The last sub-step before a predicted event is aimed this far past it (a
// fraction of the sub-step), so that the event falls inside it.
inline constexpr double kAimMargin = 0.02;
// A sub-step in a contact spans at most this many radians of the contact's
// own oscillation in w (Dormand-Prince is stable to ~3.3 on the imaginary
// axis): a small budget at a low sensor rate cannot blow a contact up.
inline constexpr double kStableStep = 1.0;
// The last sub-step of a step falls short of the step's end (a budget too
// small for the contact): it is extrapolated on its interpolant up to this
// fraction past its end, else the step ends where it stands.
inline constexpr double kMaxExtrapolation = 1.5;

// Free flight: the earliest time in (0, span] at which the overlap with a
// wall reaches the event tolerance, on the overlap's Taylor cubic (exact for
// the particle, whose acceleration is -a_g; to the floor's jerk for the
// floor); 0 if none.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
S predict_start(const Model<S, N, Dev>& m, const Stepper& st, const Vec& y, const Vec& f, S span) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  using VecX = typename Model<S, N, Dev>::VecX;
  const auto& dm = m.dev;
  const VecX fz = f.template head<NX>();
  const S r = st.rel_pos(y), v = st.rel_vel(y);
  const S acc = f(NX + 1) - m.dev_v(fz);
  const S jerk = -st.al - m.dev_v(m.lti.derivative(fz, st.al, S(0)));
  S best = S(0);
  for (int side = -1; side <= 1; side += 2) {
    const S sg = S(side);
    const S g0 = (side < 0 ? overlap_left<S>(dm, r) : overlap_right<S>(dm, r)) - dm.event_tol;
    if (!(g0 <= S(0))) continue;  // already past the tolerance: due_event decides
    const S g1 = sg * v, g2 = sg * acc, g3 = sg * jerk;
    const S g_end = g0 + span * (g1 + span * (S(0.5) * g2 + span * g3 / S(6)));
    const S d_end = g1 + span * (g2 + S(0.5) * span * g3);
    const auto c = numeric::Cubic<S>::make(g0, g1, g_end, d_end, span);
    if (!(c.max_value() > S(0))) continue;
    const S th = c.first_upcrossing(20);
    const S t = span * polish_root<kBoundedRootIterations>(c, th, S(0), S(1));
    if (t > S(0) && (best == S(0) || t < best)) best = t;
  }
  return best;
}

// In a contact, from the local model q(w) = q0 + p w + c w^2 / 2 (p = d', c =
// dd'/dw, both from the right-hand side f): w_end, where the contact ends
// (infinite if the model does not end it, or only through its curvature:
// near the deepest point the model ends the contact far too early), and
// w_step, where the time since the step began reaches tau (t(w) = integral
// of 4 q^3 over the model; infinite if the contact ends first).
template <typename S>
struct ContactAim {
  S w_end, w_step;
  // The longest sub-step the contact allows: kStableStep over its frequency
  // in w. Near the deepest point the elastic force makes (q, q') oscillate
  // in w at ~sqrt(dp/dq), dp/dq ~ 9 p'/q (p' ~ q^9), with p' = 2 e.
  S w_max;
};

template <typename S, int N, typename Dev, typename Stepper, typename Vec>
ContactAim<S> predict_contact(const Model<S, N, Dev>& m, const Stepper& st, const Vec& y, const Vec& f, S tau) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  constexpr S kInf = std::numeric_limits<S>::infinity();
  const S a = y(Stepper::kQ), p = f(Stepper::kQ);
  const S sg = st.mode == Mode::kContactLeft ? S(-1) : S(1);
  const S e = S(0.5) * sg * (f(NX + 1) - m.dev_v(f.template head<NX>()));
  // The model's first zero after now (a >= 0).
  S root = kInf;
  if (e == S(0)) {
    if (p < S(0)) root = -a / p;
  } else {
    const S disc = p * p - S(4) * a * e;
    if (disc >= S(0)) {
      const S sq = std::sqrt(disc);
      const S k = p < S(0) ? S(0.5) * (sq - p) : -S(0.5) * (p + sq);  // -(p + sign(p) sq) / 2
      const S r1 = k != S(0) ? k / e : kInf, r2 = k != S(0) ? a / k : kInf;
      if (r1 > S(0)) root = r1;
      if (r2 > S(0) && r2 < root) root = r2;
    }
  }
  const bool trusted = p < S(0) && std::fabs(e) * root * root <= S(0.5) * a;
  // t(w) - t0 = 4 integral of (a + p u + e u^2)^3, a polynomial of degree 7.
  const S a2 = a * a, p2 = p * p, e2 = e * e;
  const S c1 = S(4) * a2 * a, c2 = S(6) * a2 * p, c3 = S(4) * (a * p2 + a2 * e), c4 = p2 * p + S(6) * a * p * e,
          c5 = S(2.4) * (p2 * e + a * e2), c6 = S(2) * p * e2, c7 = S(4) / S(7) * e2 * e;
  auto t_of = [&](S w) { return w * (c1 + w * (c2 + w * (c3 + w * (c4 + w * (c5 + w * (c6 + w * c7)))))); };
  auto q_of = [&](S w) { return a + w * (p + w * e); };
  ContactAim<S> out{kInf, kInf, kInf};
  if (e != S(0) && a > S(0)) out.w_max = static_cast<S>(kStableStep) * std::sqrt(a / (S(18) * std::fabs(e)));
  // The contact ends before tau, or so little after it that the step should
  // make room for its end.
  if (trusted && t_of(root) <= S(1.1) * tau) {
    out.w_end = root;
    return out;
  }
  // A first guess from the linear part, q = a + p w: (a + p w)^4 = a^4 + p tau.
  const S a4 = a2 * a2, x = a4 + p * tau;
  S w = kInf;
  if (std::fabs(p * tau) > S(1e-3) * a4 && x > S(0)) w = (std::sqrt(std::sqrt(x)) - a) / p;
  else if (a > S(0)) w = tau / (S(4) * a2 * a);
  if (!(w > S(0) && w < kInf)) w = p < S(0) ? -a / p : kInf;
  if (!(w > S(0) && w < kInf)) return out;
  if (root < kInf && t_of(root) <= tau) {
    // The model ends the contact early through its curvature alone: the
    // linear part's guess.
    out.w_step = w;
    return out;
  }
  // Newton on t(w) = tau inside [0, root), where t increases.
  S lo = S(0), hi = root;
  if (!(w < hi)) w = S(0.5) * hi;
  for (int it = 0; it < kBoundedPredictIterations; ++it) {
    const S g = t_of(w) - tau;
    if (g == S(0)) break;
    if (g > S(0)) hi = w;
    else lo = w;
    const S q = q_of(w), slope = S(4) * q * q * q;
    S next = slope > S(0) ? w - g / slope : kInf;
    if (!(next >= lo && next <= hi)) next = hi < kInf ? S(0.5) * (lo + hi) : S(2) * w;
    if (next == w) break;
    w = next;
  }
  out.w_step = w;
  return out;
}

// The sub-step [y0 (f0) -> y1 (f1), length du]: the state at theta on its
// cubic Hermite interpolant, with its bookkeeping (track_substep).
template <typename S, int N, typename Dev, typename Vec>
Vec interpolate_to(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, Mode mode, const Vec& y0, const Vec& f0,
                   const Vec& y1, const Vec& f1, S du, S theta) {
  constexpr int kT = Model<S, N, Dev>::kNx + 6;
  const Vec y = numeric::hermite_point(y0, f0, y1, f1, du, theta);
  track_substep(m, d, mode, y0, y, y(kT) - y0(kT), y(kT), false);
  return y;
}

}  // namespace detail

// Sub-stepped step from the current state to the next sample a1 with
// bounded work (see the top). Same state, counters and write-back as
// substep_through.
template <typename S, int N, typename Dev>
void substep_bounded(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a0, S a1) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  using Stepper = detail::SubStepper<S, N, Dev>;
  using Vec = typename Stepper::Vec;
  constexpr int kT = Stepper::kT;
  constexpr S kInf = std::numeric_limits<S>::infinity();
  const auto& dm = m.dev;
  const S h = m.period;
  const int budget = m.loop.bounded_substeps;
  const S margin = S(1) + static_cast<S>(detail::kAimMargin);
  // A contact ends where q returns to zero if the walls overlap by no more
  // than this (what the interpolant leaves), else q is set back on the
  // overlap (apply_event).
  const S end_tol = numeric::max_of(dm.event_tol, S(1e-6) * dm.pos_scale);
  const S sync_tol = detail::contact_rtol(m) * dm.pos_scale;  // q against the overlap (resync_q)

  Stepper st{m, a0, (a1 - a0) / h, d.mode};
  Vec y = detail::load_state<S, N, Dev, Vec>(d);
  Vec f = st(S(0), y);
  int taken = 0, events = 0;
  bool short_of_budget = false;
  ++d.count.careful_steps;

  // An event may be applied: a contact's end while a slot is left, anything
  // else only with a slot left for the end of the contact it may start.
  auto may_apply = [&] { return in_contact(st.mode) ? events < kBoundedEvents : events + 2 <= kBoundedEvents; };
  // The last slot must end the contact.
  auto slot_end_tol = [&] { return events + 1 == kBoundedEvents ? kInf : end_tol; };
  // After an event: its slot taken, the rate at the new state.
  auto after_event = [&] {
    ++events;
    f = st(S(0), y);
  };
  auto apply = [&](int side) {
    apply_event(m, d, st, y, side, slot_end_tol());
    after_event();
  };
  // The rest of the step when no sub-step is left for it: free flight (a
  // contact that ended in the last sub-step) by one Euler step; in a contact
  // (a budget too small for it) the step ends where it stands, its time
  // short of h: the contact lasts longer by that much.
  auto finish_without_substep = [&] {
    short_of_budget = true;
    const Vec y0 = y;
    if (!st.regular()) y += (h - y(kT)) * f;
    y(kT) = h;
    track_substep(m, d, st.mode, y0, y, h - y0(kT), h, false);
  };

  while (y(kT) < h) {
    // 1. An event due before any time passes (see due_event).
    if (may_apply() && detail::apply_due_event(m, d, st, y, slot_end_tol()) != 0) {
      after_event();
      continue;
    }
    if (taken == budget) {  // only after an event in the last sub-step
      finish_without_substep();
      break;
    }
    // 2. Aim the sub-step.
    const int left = budget - taken;
    const bool reg = st.regular();
    S du;
    bool to_end = false;  // a free sub-step that ends the step exactly
    if (!reg) {
      const S span = h - y(kT);
      const S start = st.mode == Mode::kFree && left >= 2 && events + 2 <= kBoundedEvents
                          ? detail::predict_start(m, st, y, f, span)
                          : S(0);
      du = start > S(0) ? numeric::min_of(start * margin, span) : span;
      to_end = du == span;
    } else {
      const detail::ContactAim<S> aim = detail::predict_contact(m, st, y, f, h - y(kT));
      const bool end_first = aim.w_end < kInf && left >= 2;
      const S target = end_first ? aim.w_end : aim.w_step;
      const int share = end_first ? left - 1 : left;
      du = target / static_cast<S>(share);
      if (share == 1) du *= margin;
      if (!(du > S(0) && du < kInf)) du = dm.w_step0;  // no prediction: a first step's size
      du = numeric::min_of(du, aim.w_max);
    }
    // 3. The sub-step.
    const auto r = numeric::dopri5_step<Vec, false>(st, S(0), y, f, du);
    ++taken;
    ++d.count.substeps;
    if (st.mode != Mode::kFree) ++d.count.contact_substeps;

    // 4. The first event inside it, if the budget can follow it.
    S theta = S(2);
    int side = 0;
    const bool any = detail::first_event(m, st, y, f, r.y, r.f, du, h, 20, &theta, &side) && theta <= S(1);
    const bool step_end = any && side == 0;
    if (any && (step_end || (may_apply() && (reg || taken < budget)))) {
      if (!riding(st.mode)) {
        S s0, s1;
        const S g0 = detail::event_value(m, st, y, f, side, h, &s0);
        const S g1 = detail::event_value(m, st, r.y, r.f, side, h, &s1);
        const auto c = numeric::Cubic<S>::make(g0, s0, g1, s1, du);
        theta = detail::polish_root<detail::kBoundedRootIterations>(c, theta, S(0), S(1));
      }
      y = detail::interpolate_to(m, d, st.mode, y, f, r.y, r.f, du, theta);
      if (step_end) {
        y(kT) = h;
        break;
      }
      apply(side);
      continue;
    }
    if (any) short_of_budget = true;  // an event that waits for the next step

    // 5. The whole sub-step.
    track_substep(m, d, st.mode, y, r.y, r.y(kT) - y(kT), r.y(kT), false);
    const Vec y0 = y, f0 = f;
    y = r.y;
    f = r.f;
    if (to_end) y(kT) = h;
    if (reg) {
      if (detail::resync_q(m, st, y, sync_tol)) f = st(S(0), y);
      if (taken == budget && y(kT) < h) {
        // Out of sub-steps short of the step's end: extrapolate to it on the
        // last sub-step's interpolant (Newton on its cubic of t from theta =
        // 1) if it gets there soon enough, else end the step here.
        const S reach = static_cast<S>(detail::kMaxExtrapolation);
        const auto c = numeric::Cubic<S>::make(y0(kT) - h, f0(kT), y(kT) - h, f(kT), du);
        if (c.value(reach) > S(0)) {
          short_of_budget = true;
          const S th = detail::polish_root<detail::kBoundedRootIterations>(c, S(1), S(1), reach);
          const Vec y1 = y;
          y = numeric::hermite_point(y0, f0, y1, f, du, th);
          y(kT) = h;
          track_substep(m, d, st.mode, y1, y, h - y1(kT), h, false);
        } else {
          finish_without_substep();
        }
        break;
      }
    }
  }
  if (short_of_budget) ++d.count.cap_hits;
  if (taken > d.count.max_substeps_in_step) d.count.max_substeps_in_step = taken;
  if (events > d.count.max_events_in_step) d.count.max_events_in_step = events;

  // Per-floor peaks over the whole step, from its two ends (the floors are
  // smooth on a sensor step; the top floor was followed sub-step by
  // sub-step above).
  if (m.loop.floor_peaks) {
    const auto z1 = y.template head<NX>();
    detail::update_peaks<S, N>(m.floor_x(d.z), m.floor_v(d.z), m.floor_x(z1), m.floor_v(z1), h, d.peak_x,
                               d.peak_drift);
  }

  // Write the state back (as substep_through).
  detail::store_state(d, st, y);
}

}  // namespace vines
