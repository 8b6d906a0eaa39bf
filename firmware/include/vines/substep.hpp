// VI NES stage of the loop: the particle between the walls.
//   - free_flight: exact step of the particle under -a_g alone (and the work
//     of its inertial load);
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

#include "vines/data.hpp"
#include "vines/model.hpp"
#include "vines/numeric/dopri5.hpp"
#include "vines/numeric/hermite.hpp"
#include "vines/numeric/inline.hpp"
#include "vines/numeric/minmax.hpp"
#include "vines/peaks.hpp"

namespace vines {

// Below this approach speed [m/s] an instantaneous impact is taken as plastic
// and the particle rides the wall (no Zeno cascade of ever smaller bounces);
// impacts slower than it are not counted. The threshold also rises to the
// speed whose rebound, against the acceleration that pushes the particle
// into the wall, would not lift it by the contact counting depth: such
// bounces are below what the model resolves, and a cascade of them would be
// resolved one by one (hundreds of thousands of impacts).
inline constexpr double kStickSpeed = 1e-6;

// Overlap with the left and right walls for a relative position r = s - x_f
// (positive means interpenetration).
template <typename S, typename DM>
S overlap_left(const DM& dm, S r) { return dm.wall_left - r; }
template <typename S, typename DM>
S overlap_right(const DM& dm, S r) { return r - dm.wall_right; }

// Elastic energy stored in the current contact, (2/5) C d^{5/2}.
template <typename S, int N, typename Dev>
S contact_energy(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  if (d.mode != Mode::kContactLeft && d.mode != Mode::kContactRight) return S(0);
  const S r = d.s - m.dev_x(d.z);
  const S dl = d.mode == Mode::kContactLeft ? overlap_left<S>(m.dev, r) : overlap_right<S>(m.dev, r);
  return dl > S(0) ? S(0.4) * m.dev.c * dl * dl * std::sqrt(dl) : S(0);
}

// Exact free flight of the particle over one step (acceleration -a_g, linear
// from a0 to a1): from (s, s') to (*s1, *sd1).
template <typename S, int N, typename Dev>
VINES_INLINE void free_flight(const Model<S, N, Dev>& m, S s, S sd, S a0, S a1, S* s1, S* sd1) {
  const auto& dm = m.dev;
  *s1 = s + sd * m.hs - a0 * dm.ff_a0 - a1 * dm.ff_a1;
  *sd1 = sd - (a0 + a1) * dm.ff_v;
}

// Work of the particle's inertial load over that step: -m integral a v dt,
// a = a0 + al t, v = v0 - a0 t - al t^2 / 2.
template <typename S, int N, typename Dev>
double free_flight_work(const Model<S, N, Dev>& m, S v0, S a0, S a1) {
  const S h = m.hs, al = (a1 - a0) / h;
  const S h2 = h * h, h3 = h2 * h, h4 = h3 * h;
  const S w = a0 * v0 * h - a0 * a0 * h2 / S(2) - a0 * al * h3 / S(6) + al * v0 * h2 / S(2) -
              al * a0 * h3 / S(3) - al * al * h4 / S(8);
  return static_cast<double>(m.dev.m * w);
}

namespace detail {

// State of the sub-stepper: [z; s; s'; contact loss; input; damping; E_e;
// t; q]: t the time since the step began, q = d^{1/4} in a contact.
template <typename S, int NX>
using SubVec = Eigen::Matrix<S, NX + 8, 1>;

template <typename S, int N, typename Dev>
struct SubStepper {
  static constexpr int NX = Model<S, N, Dev>::kNx;
  using Vec = SubVec<S, NX>;
  using VecX = typename Model<S, N, Dev>::VecX;
  const Model<S, N, Dev>& m;
  S a0, al;   // ground acceleration a0 + al t over the step
  Mode mode;

  static constexpr int kT = NX + 6, kQ = NX + 7;

  S ag(S t) const { return a0 + al * t; }
  // In a contact the independent variable is w (dt/dw = 4 q^3), else t.
  bool regular() const { return mode == Mode::kContactLeft || mode == Mode::kContactRight; }
  S rel_pos(const Vec& y) const { return y(NX) - m.dev_x(y.template head<NX>()); }
  S rel_vel(const Vec& y) const { return y(NX + 1) - m.dev_v(y.template head<NX>()); }

  // Overlap rate d' of the current contact.
  S overlap_rate(const Vec& y) const { return mode == Mode::kContactLeft ? -rel_vel(y) : rel_vel(y); }

  // Force on the particle (positive to the right) and the power lost in it;
  // *rate, if asked for: the overlap rate d' in a contact, 0 otherwise.
  VINES_INLINE void force(const Vec& y, S* fp, S* loss, S* rate = nullptr) const {
    *fp = S(0);
    *loss = S(0);
    if (rate) *rate = S(0);
    const auto& dm = m.dev;
    if (regular()) {
      if constexpr (Dev::kLaw != ContactLaw::kRestitution) {
        const S ddl = overlap_rate(y);
        const contact::Force<S> f = dm.law.regular(y(kQ), ddl);
        *fp = mode == Mode::kContactLeft ? f.total() : -f.total();
        *loss = f.dissipative * ddl;
        if (rate) *rate = ddl;
      }
    } else if (mode == Mode::kStuckLeft || mode == Mode::kStuckRight) {
      // Riding the wall: the force that gives the particle the floor's
      // acceleration, m* (floor acceleration without the device + a_g).
      const S a = ag(y(kT));
      const VecX z = y.template head<NX>();
      const S floor_acc = m.dev_v(m.lti.derivative(z, a, S(0)));
      *fp = dm.m_star * (floor_acc + a);
    }
  }

  // y' (free, stuck) or dy/dw (contact). The frame is written straight from
  // the modal coefficients, every rate scaled by w = dt/du once.
  Vec operator()(S /*u*/, const Vec& y) const {
    constexpr int P = NX / 2;
    const auto& l = m.lti;
    const auto& dm = m.dev;
    const S a = ag(y(kT));
    S fp, loss, dq;
    force(y, &fp, &loss, &dq);
    const S w = regular() ? S(4) * y(kQ) * y(kQ) * y(kQ) : S(1);
    const auto q = y.template head<P>().array();
    const auto v = y.template segment<P>(P).array();
    Vec dy;
    dy.template head<P>() = w * v;
    dy.template segment<P>(P) =
        w * (l.ak.array() * q + l.ac.array() * v + (l.bgv.array() * a - l.bfv.array() * fp));
    dy(NX) = w * y(NX + 1);
    dy(NX + 1) = w * (fp * dm.inv_m - a);
    dy(NX + 2) = w * loss;
    if (m.loop.energy_ledger) {
      const auto z = y.template head<NX>();
      dy(NX + 3) = w * (m.input_power.eval(z, a) - a * dm.m * y(NX + 1));
      dy(NX + 4) = w * m.damping_power.eval(z, a);
    } else {
      dy(NX + 3) = dy(NX + 4) = S(0);
    }
    // The strain energy is a form in the positions alone (w_j^2 q_j^2 / 2).
    dy(NX + 5) = w * m.strain.eval_positions(y.template head<P>());
    dy(kT) = w;
    dy(kQ) = dq;
    return dy;
  }

  // Error scales of the frame and the particle: a typical contact position
  // and speed (the modal coordinates weighted by the total mass).
  static Eigen::Array<S, NX + 2, 1> error_scale(const Model<S, N, Dev>& m) {
    const auto& dm = m.dev;
    Eigen::Array<S, NX + 2, 1> sc;
    sc.template head<NX / 2>().setConstant(dm.pos_scale * dm.modal_scale);
    sc.template segment<NX / 2>(NX / 2).setConstant(dm.vel_scale * dm.modal_scale);
    sc(NX) = dm.pos_scale;
    sc(NX + 1) = dm.vel_scale;
    return sc;
  }

  // Error of a sub-step relative to those scales (energies excluded), and
  // of t and (in a contact) q; rtol_scale = rtol * error_scale(m).
  S error_norm(const Vec& e, const Vec& y0, const Vec& y1, S rtol,
               const Eigen::Array<S, NX + 2, 1>& rtol_scale) const {
    const auto ey = e.template head<NX + 2>().array().abs();
    const auto mag = y0.template head<NX + 2>().array().abs().max(y1.template head<NX + 2>().array().abs());
    const S worst = (ey / (rtol_scale + rtol * mag)).maxCoeff();
    const S rt = std::fabs(e(kT)) / (rtol * m.hs);
    const S rq = regular() ? std::fabs(e(kQ)) / (rtol * m.dev.q_scale) : S(0);
    const S all = numeric::max_of(worst, numeric::max_of(rt, rq));
    return std::isfinite(all + ey.sum()) ? all : std::numeric_limits<S>::infinity();
  }
};

}  // namespace detail

// Bookkeeping of an accepted sub-step from y0 to y1 (length h, ending at t1
// within the run): peaks (per floor too, if floors and the loop keeps
// them), contact depth.
template <typename S, int N, typename Dev, typename Vec>
void track_substep(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, Mode mode, const Vec& y0, const Vec& y1, S h,
                   double t1, bool floors = true) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  const auto z0 = y0.template head<NX>();
  const auto z1 = y1.template head<NX>();
  detail::update_top_peak_cubic(d, m.top_x(z0), m.top_v(z0), m.top_x(z1), m.top_v(z1), h, t1);
  if (floors && m.loop.floor_peaks)
    detail::update_peaks<S, N>(m.floor_x(z0), m.floor_v(z0), m.floor_x(z1), m.floor_v(z1), h, d.peak_x,
                               d.peak_drift);
  if (mode == Mode::kContactLeft || mode == Mode::kContactRight) {
    const S r = y1(NX) - m.dev_x(z1);
    const S dl = mode == Mode::kContactLeft ? overlap_left<S>(m.dev, r) : overlap_right<S>(m.dev, r);
    if (dl > d.contact_depth) d.contact_depth = dl;
    if (dl > d.max_overlap) d.max_overlap = dl;
  }
}

// What happens at a located event (side: -1 left wall, +1 right wall). A
// contact ends where q reaches zero if the walls overlap by no more than
// end_tol there (else q goes back on the overlap, below).
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
void apply_event(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, Stepper& st, Vec& y, int side, S end_tol) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  using VecX = typename Model<S, N, Dev>::VecX;
  const auto& dm = m.dev;
#ifdef VINES_TRACE
  std::printf("event t=%.6f mode=%d side=%d r=%.6e rd=%.6e depth=%.3e\n", d.time(m), (int)st.mode, side,
              (double)st.rel_pos(y), (double)st.rel_vel(y), (double)d.contact_depth);
#endif
  switch (st.mode) {
    case Mode::kFree:
      if constexpr (Dev::kLaw == ContactLaw::kRestitution) {
        // Newton's law between the particle and the floor mass (Eq. 4).
        const S rd = st.rel_vel(y);
        const S v_app = side < 0 ? -rd : rd;
        if (v_app <= S(0)) return;
        S push, unused;  // the force that would hold the particle on the wall
        const Mode before = st.mode;
        st.mode = side < 0 ? Mode::kStuckLeft : Mode::kStuckRight;
        st.force(y, &push, &unused);
        st.mode = before;
        // The wall holds the particle with a force towards the box: + on the left.
        const S a_in = std::fmax(side < 0 ? push : -push, S(0)) / dm.m_star;
        const S v_stick = std::fmax(static_cast<S>(kStickSpeed), std::sqrt(S(2) * a_in * dm.count_depth));
        const bool plastic = dm.eps * v_app < v_stick;
        const S e = plastic ? S(0) : dm.eps;
        const S j = contact::restitution_impulse(dm.m, S(1) / m.inv_floor_mass, v_app, e);
        const S jp = side < 0 ? j : -j;  // impulse on the particle
        y(NX + 1) += jp * dm.inv_m;
        VecX z = y.template head<NX>();
        m.lti.impulse(z, -jp);  // the floor takes the opposite impulse
        y.template head<NX>() = z;
        // The impact was placed up to the event tolerance past the wall: put
        // the particle back on it, so that the next approach is seen again.
        y(NX) += (side < 0 ? dm.wall_left : dm.wall_right) - st.rel_pos(y);
        y(NX + 2) += S(0.5) * dm.m_star * (S(1) - e * e) * v_app * v_app;
        if (v_app > static_cast<S>(kStickSpeed)) ++d.count.contacts;
        if (plastic) {
          st.mode = side < 0 ? Mode::kStuckLeft : Mode::kStuckRight;
          S fp, loss;
          st.force(y, &fp, &loss);
          if ((side < 0 && fp < S(0)) || (side > 0 && fp > S(0))) st.mode = Mode::kFree;
        }
      } else {
        st.mode = side < 0 ? Mode::kContactLeft : Mode::kContactRight;
        const S dl = side < 0 ? overlap_left<S>(dm, st.rel_pos(y)) : overlap_right<S>(dm, st.rel_pos(y));
        y(Stepper::kQ) = std::sqrt(std::sqrt(std::fmax(dl, S(0))));
        d.contact_depth = S(0);
      }
      break;
    case Mode::kContactLeft:
    case Mode::kContactRight: {
      // q reached zero: the contact ends, unless the walls still overlap (q
      // and the overlap drifted apart): then q goes back on the overlap.
      const S r = st.rel_pos(y);
      const S dl = st.mode == Mode::kContactLeft ? overlap_left<S>(dm, r) : overlap_right<S>(dm, r);
      if (dl > end_tol) {
        y(Stepper::kQ) = std::sqrt(std::sqrt(dl));
        break;
      }
      if (d.contact_depth > m.dev.count_depth) ++d.count.contacts;
      st.mode = Mode::kFree;
      break;
    }
    default:
      st.mode = Mode::kFree;
      break;
  }
}

// The same, with the event tolerance for the end of a contact.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
void apply_event(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, Stepper& st, Vec& y, int side) {
  apply_event(m, d, st, y, side, m.dev.event_tol);
}

// An event due right now, before any time passes: 0 if none, else the wall
// side (-1, +1). Contacts end once the overlap is gone; free particles start
// a contact if they overlap a wall while approaching it; riding particles
// leave the wall once the holding force would pull.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
int due_event(const Model<S, N, Dev>& m, const Stepper& st, const Vec& y) {
  const auto& dm = m.dev;
  const S r = st.rel_pos(y), rd = st.rel_vel(y), tol = m.dev.event_tol;
  switch (st.mode) {
    case Mode::kFree: {
      // An impact needs an approach speed the law resolves (a particle just
      // released from a wall sits on it with a rounding-level speed).
      const S v_min = Dev::kLaw == ContactLaw::kRestitution ? static_cast<S>(kStickSpeed) : S(0);
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
  const S r = st.rel_pos(y), rd = st.rel_vel(y);
  switch (st.mode) {
    case Mode::kFree:  // overlap with wall `side` exceeds the tolerance
      *slope = side < 0 ? -rd : rd;
      return (side < 0 ? overlap_left<S>(dm, r) : overlap_right<S>(dm, r)) - m.dev.event_tol;
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
// length hs? Which first? From the cubic Hermite interpolant of each event
// function (linear for the holding force, whose slope is not known): true
// and *theta (the fraction of the sub-step: the first up-crossing on the
// cubic, bisected `halvings` times after a 16-point grid), *side; false if
// none.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
VINES_INLINE bool first_event(const Model<S, N, Dev>& m, const Stepper& st, const Vec& y0, const Vec& f0,
                              const Vec& y1, const Vec& f1, S hs, S h, int halvings, S* theta, int* side) {
  const bool reg = st.regular();
  bool any = false;
  for (int sd = -1; sd <= 1; ++sd) {
    if (sd == 0 && !reg) continue;           // t = h: only in w
    if (st.mode != Mode::kFree && sd == 1) break;
    S s0, s1;
    const S g0 = event_value(m, st, y0, f0, sd, h, &s0), g1 = event_value(m, st, y1, f1, sd, h, &s1);
    const auto cub = numeric::Cubic<S>::make(g0, s0, g1, s1, hs);
    const bool stuck = st.mode == Mode::kStuckLeft || st.mode == Mode::kStuckRight;
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

// The sub-steppers' state vector from the data block: floors (modal), the
// particle, four zeroed integrals (contact loss, input, damping, E_e), time
// since the step began, q.
template <typename S, int N, typename Dev, typename Vec>
Vec load_state(const Data<S, N, Dev>& d) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  Vec y;
  y.template head<NX>() = d.z;
  y(NX) = d.s;
  y(NX + 1) = d.sd;
  y.template segment<4>(NX + 2).setZero();
  y(SubStepper<S, N, Dev>::kT) = S(0);
  y(SubStepper<S, N, Dev>::kQ) = d.q;
  return y;
}

// Writes a sub-stepper's end state y back: mode, state, the step's
// integrals into the ledger and E_e, the contact force.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
void store_state(Data<S, N, Dev>& d, const Stepper& st, const Vec& y) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  d.mode = st.mode;
  d.z = y.template head<NX>();
  d.s = y(NX);
  d.sd = y(NX + 1);
  d.q = st.regular() ? y(Stepper::kQ) : S(0);
  d.ledger.contact += static_cast<double>(y(NX + 2));
  d.ledger.input += static_cast<double>(y(NX + 3));
  d.ledger.damping += static_cast<double>(y(NX + 4));
  d.ee_sum += static_cast<double>(y(NX + 5));
  S fp, loss;
  st.force(y, &fp, &loss);
  d.contact_force = fp;
}

}  // namespace detail

// Sub-stepped step from the current state to the next sample a1. The
// independent variable u is t outside contacts and w inside (see the top).
template <typename S, int N, typename Dev>
void substep_through(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a0, S a1) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  using Stepper = detail::SubStepper<S, N, Dev>;
  using Vec = typename Stepper::Vec;
  constexpr int kT = Stepper::kT, kQ = Stepper::kQ;
  const auto& dm = m.dev;
  const S h = m.hs;
  constexpr S kEps = std::numeric_limits<S>::epsilon();
  // Tolerances that the scalar can honour.
  const S rtol = std::fmax(static_cast<S>(m.loop.contact_rtol), S(64) * kEps);
  const S event_tol = m.dev.event_tol;
  const int cap = m.loop.max_substeps_per_step;

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
  // Event function of the current mode (detail::event_value).
  auto event_value = [&](const Vec& yy, const Vec& ff, int side, S* slope) {
    return detail::event_value(m, st, yy, ff, side, h, slope);
  };

  int immediate = 0;
  S ln_en_old = std::log(S(1e-4));  // error of the last accepted sub-step (PI control)
  bool rejected_last = false;
  while (y(kT) < h) {
    // An event already due at the start of the sub-step (the state sits on
    // the far side of a switching surface within rounding): apply it now.
    if (immediate < 4) {
      const int due = due_event(m, st, y);
      if (due != 0) {
        ++immediate;
        ++d.count.events;
        const bool was_regular = st.regular();
        apply_event(m, d, st, y, due);
        if (st.regular() && !was_regular) hc_w = dm.w_step0;
        f = st(u, y);
        continue;
      }
    }
    const bool reg = st.regular();
    const bool forced = n >= cap - 1;
    S hs;
    if (!reg) hs = std::fmin(hc_t, h - y(kT));
    else if (forced) hs = (h - y(kT)) / std::fmax(f(kT), kEps);  // to t = h at the current rate
    else hs = hc_w;
    auto r = numeric::dopri5_step<Vec>(st, u, y, f, hs);
    const S en = st.error_norm(r.err, y, r.y, rtol, rtol_scale);
    ++n;
    if (!forced && !(en <= S(1))) {
      ++d.count.rejected;
      (reg ? hc_w : hc_t) = hs * std::fmax(S(0.1), S(0.9) * std::pow(std::fmax(en, S(1e-10)), S(-0.2)));
      rejected_last = true;
      continue;
    }
    if (forced) capped = true;

    // Does an event happen inside this sub-step? Which first? (Not in a
    // forced sub-step: past the cap, events wait for the next step.) A first
    // guess for the Newton steps below: 1/16 of the sub-step bisected 20
    // times (6e-8 of it).
    S theta = S(2);
    int side = 0;
    const bool any = !forced && detail::first_event(m, st, y, f, r.y, r.f, hs, h, 20, &theta, &side);

    if (any && theta <= S(1)) {
      // Place the event on the true sub-step, bracket [0, hs], from the
      // cubic's estimate: Newton steps on the event function (its slope comes
      // with each trial step) aimed at the middle of the acceptance band
      // [0, tol], Illinois steps where Newton would leave the bracket. The
      // step end (side 0) is placed to rounding of t.
      const S tol = side == 0 ? S(4) * kEps * h : event_tol;
      S lo = S(0), hi = hs, slope;
      S glo = event_value(y, f, side, &slope);
      S ghi = event_value(r.y, r.f, side, &slope);
      if (!(ghi > S(0))) ghi = S(1);
      S tau = theta * hs;
      auto rr = numeric::dopri5_step<Vec>(st, u, y, f, tau);
      int last = 0;
      for (int it = 0; it < 40; ++it) {
        const S g = event_value(rr.y, rr.f, side, &slope);
        if (std::fabs(g) <= tol && g >= S(0)) break;
        if (g > S(0)) { hi = tau; ghi = g; if (last == 1) glo *= S(0.5); last = 1; }
        else { lo = tau; glo = g; if (last == -1) ghi *= S(0.5); last = -1; }
        if (hi - lo <= S(4) * kEps * (std::fabs(u) + hi)) {
          tau = hi;
        } else {
          tau = slope > S(0) ? tau - (g - S(0.5) * tol) / slope : lo;
          if (!(tau > lo && tau < hi))
            tau = (ghi > S(0) && glo < S(0)) ? (lo * ghi - hi * glo) / (ghi - glo) : S(0.5) * (lo + hi);
          if (!(tau > lo && tau < hi)) tau = S(0.5) * (lo + hi);
        }
        rr = numeric::dopri5_step<Vec>(st, u, y, f, tau);
        if (tau == hi && hi - lo <= S(4) * kEps * (std::fabs(u) + hi)) break;
      }
      // Accept up to the event.
      track_substep(m, d, st.mode, y, rr.y, rr.y(kT) - y(kT), d.time(m) + static_cast<double>(rr.y(kT)));
      u += tau;
      y = rr.y;
      ++d.count.substeps;
      if (st.mode != Mode::kFree) ++d.count.contact_substeps;
      if (side == 0) {  // the step ends inside the contact
        y(kT) = h;
        break;
      }
      ++d.count.events;
      const bool was_regular = st.regular();
      apply_event(m, d, st, y, side);
      if (st.regular() && !was_regular) hc_w = dm.w_step0;
      f = st(u, y);
      continue;
    }

    // Plain accepted sub-step.
    track_substep(m, d, st.mode, y, r.y, r.y(kT) - y(kT), d.time(m) + static_cast<double>(r.y(kT)));
    u += hs;
    y = r.y;
    f = r.f;
    if (reg) {
      // q^4 and the overlap drift apart over a long (resting) contact: put q
      // back on the overlap once they differ by more than the tolerance.
      const S r_now = st.rel_pos(y);
      const S dl = std::fmax(st.mode == Mode::kContactLeft ? overlap_left<S>(dm, r_now) : overlap_right<S>(dm, r_now), S(0));
      const S q2 = y(kQ) * y(kQ);
      if (std::fabs(q2 * q2 - dl) > rtol * dm.pos_scale) {
        y(kQ) = std::sqrt(std::sqrt(dl));
        f = st(u, y);
      }
    }
    ++d.count.substeps;
    if (st.mode != Mode::kFree) ++d.count.contact_substeps;
    {
      // PI step-size control (Gustafsson; Hairer's DOPRI5 constants): no
      // growth right after a rejection.
      const S ln_en = std::log(std::fmax(en, S(1e-4)));
      S fac = S(0.9) * std::exp(S(-0.17) * ln_en + S(0.04) * ln_en_old);
      fac = std::fmin(rejected_last ? S(1) : S(5), std::fmax(S(0.2), fac));
      (reg ? hc_w : hc_t) = hs * fac;
      ln_en_old = ln_en;
      rejected_last = false;
    }
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
