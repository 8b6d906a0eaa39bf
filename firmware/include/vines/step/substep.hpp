// VI NES stage of the loop: the particle between the walls.
//   - free_flight (substep_common.hpp): exact step of the particle under -a_g
//     alone (and the work of its inertial load);
//   - substep_through: adaptive Dormand-Prince sub-steps over the step with
//     the frame in modal coordinates, contact starts and ends located to
//     rounding, impacts of the instantaneous law applied at their instant, a
//     cap on sub-steps.
// Inside a finite-duration contact the force has d^{1/2} (Kuwabara) or
// d^{1/4} (Tsuji) in it: in time the solution is not smooth where a contact
// starts and ends, and an adaptive method crawls there. So contacts are
// integrated in a regularised variable w with dt/dw = 4 q^3, q = d^{1/4}
// carried as a state (dq/dw = d'): every law is then a polynomial in q and
// the solution is smooth in w through the whole contact, end included (q
// crosses zero with slope -(exit speed)). Time is a state; the end of the
// sensor step is located as an event.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "vines/model/contact_mode.hpp"
#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/dopri5.hpp"
#include "vines/numeric/inline.hpp"
#include "vines/numeric/minmax.hpp"
#include "vines/numeric/step_control.hpp"
#include "vines/step/events.hpp"
#include "vines/step/peaks.hpp"
#include "vines/step/substep_common.hpp"

namespace vines {

// Sub-stepped step from the current state to the next sample a1. The
// independent variable u is t outside contacts and w inside (see the top).
template <typename S, int N, typename Dev>
void substep_through(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a0, S a1) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  using Stepper = detail::SubStepper<S, N, Dev>;
  using Vec = typename Stepper::Vec;
  constexpr int kT = Stepper::kT;
  const auto& dm = m.dev;
  const S h = m.period;
  constexpr S kEps = std::numeric_limits<S>::epsilon();
  const S rtol = detail::contact_rtol(m);
  const int cap = m.loop.max_substeps_per_step;
  // q and the overlap agree within rtol * pos_scale (they are put back
  // together past that, resync_q): a contact ends where q reaches zero with
  // no more overlap left than that (apply_event).
  const S end_tol = numeric::max_of(dm.event_tol, rtol * dm.pos_scale);

  Stepper st{m, a0, (a1 - a0) / h, d.mode};
  const Eigen::Array<S, NX + 2, 1> rtol_scale = rtol * Stepper::error_scale(m);
  Vec y = detail::load_state<S, N, Dev, Vec>(d);
  Vec f = st(S(0), y);
  S u = S(0);  // the integrator's variable; only differences matter
  // Step sizes carried across steps, one per variable.
  S hc_t = d.substep > S(0) ? std::fmin(d.substep, h) : h;
  S hc_w = d.substep_w > S(0) ? d.substep_w : dm.w_step0;
  int n = 0;
  bool capped = false;
  ++d.count.careful_steps;
  int immediate = 0;
  numeric::PiControl<S> control;  // the step-size controller (step_control.hpp)
  while (y(kT) < h) {
    // An event already due at the start of the sub-step (the state sits on
    // the far side of a switching surface within rounding): apply it now.
    if (immediate < 4) {
      const bool was_regular = st.regular();
      if (detail::apply_due_event(m, d, st, y, end_tol) != 0) {
        ++immediate;
        if (st.regular() && !was_regular) hc_w = dm.w_step0;
        f = st(u, y);
        continue;
      }
    }
    const bool reg = st.regular();
    const bool forced = n >= cap - 1;
    S du;
    if (!reg) du = std::fmin(hc_t, h - y(kT));
    else if (forced) du = (h - y(kT)) / std::fmax(f(kT), kEps);  // to t = h at the current rate
    else du = hc_w;
    auto r = numeric::dopri5_step<Vec>(st, u, y, f, du);
    const S en = st.error_norm(r.err, y, r.y, rtol, rtol_scale);
    ++n;
    if (!forced && !control.accepts(en)) {
      ++d.count.rejected;
      (reg ? hc_w : hc_t) = control.rejected(du, en);
      continue;
    }
    if (forced) capped = true;

    // Does an event happen inside this sub-step? Which first? (Not in a
    // forced sub-step: past the cap, events wait for the next step.) A first
    // guess for the Newton steps below: 1/16 of the sub-step bisected 20
    // times (6e-8 of it).
    S theta = S(2);
    int side = 0;
    const bool any = !forced && detail::first_event(m, st, y, f, r.y, r.f, du, h, 20, &theta, &side);

    if (any && theta <= S(1)) {
      // Place the event on the true sub-step (detail::locate_event).
      S tau;
      const auto rr = detail::locate_event(m, st, u, y, f, r, du, h, theta, side, rtol, &tau);
      // Accept up to the event.
      track_substep(m, d, st.mode, y, rr.y, rr.y(kT) - y(kT), rr.y(kT));
      u += tau;
      y = rr.y;
      ++d.count.substeps;
      if (st.mode != Mode::kFree) ++d.count.contact_substeps;
      if (side == 0) {  // the step ends inside the contact
        y(kT) = h;
        break;
      }
      const bool was_regular = st.regular();
      apply_event(m, d, st, y, side, end_tol);
      if (st.regular() && !was_regular) hc_w = dm.w_step0;
      f = st(u, y);
      continue;
    }

    // Plain accepted sub-step.
    track_substep(m, d, st.mode, y, r.y, r.y(kT) - y(kT), r.y(kT));
    u += du;
    y = r.y;
    f = r.f;
    if (reg && detail::resync_q(m, st, y, rtol * dm.pos_scale)) f = st(u, y);
    ++d.count.substeps;
    if (st.mode != Mode::kFree) ++d.count.contact_substeps;
    (reg ? hc_w : hc_t) = control.accepted(du, en);
    if (forced || y(kT) >= h * (S(1) - S(8) * kEps)) break;
  }
  if (capped) ++d.count.cap_hits;
  if (n > d.count.max_substeps_in_step) d.count.max_substeps_in_step = n;

  // Write the state back.
  d.substep = hc_t;
  d.substep_w = hc_w;
  detail::store_state(d, st, y);
}

}  // namespace vines
