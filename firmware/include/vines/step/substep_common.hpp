// The sub-steppers' common parts (substep.hpp: adaptive; substep_bounded.hpp:
// bounded work): the particle's exact free flight and its work, the
// right-hand side over a step in t or, inside a contact, in w (SubStepper),
// the bookkeeping of an accepted sub-step, what a located event does to the
// state (EventAct, apply_event), and the state's load from and write-back to
// the data block. The variables are those of substep.hpp's top comment.
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

namespace vines {

// Elastic energy stored in the current contact (the law's potential).
template <typename S, int N, typename Dev>
S contact_energy(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  if (!in_contact(d.mode)) return S(0);
  const S r = d.s - m.dev_x(d.z);
  const S dl = d.mode == Mode::kContactLeft ? overlap_left<S>(m.dev, r) : overlap_right<S>(m.dev, r);
  return dl > S(0) ? m.dev.law.potential(dl) : S(0);
}

// Exact free flight of the particle over one step (acceleration -a_g, linear
// from a0 to a1): from (s, s') to (*s1, *sd1).
template <typename S, int N, typename Dev>
VINES_INLINE void free_flight(const Model<S, N, Dev>& m, S s, S sd, S a0, S a1, S* s1, S* sd1) {
  const auto& dm = m.dev;
  *s1 = s + sd * m.period - a0 * dm.ff_a0 - a1 * dm.ff_a1;
  *sd1 = sd - (a0 + a1) * dm.ff_v;
}

// Work of the particle's inertial load over that step: -m integral a v dt,
// a = a0 + al t, v = v0 - a0 t - al t^2 / 2.
template <typename S, int N, typename Dev>
S free_flight_work(const Model<S, N, Dev>& m, S v0, S a0, S a1) {
  const S h = m.period, al = (a1 - a0) / h;
  const S h2 = h * h, h3 = h2 * h, h4 = h3 * h;
  const S w = a0 * v0 * h - a0 * a0 * h2 / S(2) - a0 * al * h3 / S(6) + al * v0 * h2 / S(2) -
              al * a0 * h3 / S(3) - al * al * h4 / S(8);
  return m.dev.m * w;
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
  bool regular() const { return in_contact(mode); }
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
      if constexpr (!Dev::kImpulsive) {
        const S ddl = overlap_rate(y);
        const contact::Force<S> f = dm.law.regular(y(kQ), ddl);
        *fp = mode == Mode::kContactLeft ? f.total() : -f.total();
        *loss = f.dissipative * ddl;
        if (rate) *rate = ddl;
      }
    } else if (riding(mode)) {
      // Riding the wall: the force that gives the particle the floor's
      // acceleration, m* (floor acceleration without the device + a_g).
      const S a = ag(y(kT));
      const VecX z = y.template head<NX>();
      const S floor_acc = m.dev_v(m.lti.derivative(z, a, S(0)));
      *fp = dm.m_star * (floor_acc + a);
    }
  }

  // y' (free, stuck) or dy/dw (contact) into *out (not y itself). The frame
  // is written straight from the modal coefficients, every rate scaled by
  // w = dt/du once.
  void operator()(S /*u*/, const Vec& y, Vec* out) const {
    constexpr int P = NX / 2;
    const auto& l = m.lti;
    const auto& dm = m.dev;
    const S a = ag(y(kT));
    S fp, loss, dq;
    force(y, &fp, &loss, &dq);
    const S w = regular() ? S(4) * y(kQ) * y(kQ) * y(kQ) : S(1);
    const auto q = y.template head<P>().array();
    const auto v = y.template segment<P>(P).array();
    Vec& dy = *out;
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
  }
  // The same, returned.
  Vec operator()(S u, const Vec& y) const {
    Vec dy;
    (*this)(u, y, &dy);
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
    const S rt = std::fabs(e(kT)) / (rtol * m.period);
    const S rq = regular() ? std::fabs(e(kQ)) / (rtol * m.dev.q_scale) : S(0);
    const S all = numeric::max_of(worst, numeric::max_of(rt, rq));
    return std::isfinite(all + ey.sum()) ? all : std::numeric_limits<S>::infinity();
  }
};

}  // namespace detail

// Bookkeeping of an accepted sub-step from y0 to y1 (length h, ending t1
// into the sensor step): peaks (per floor too, if floors and the loop keeps
// them), contact depth.
template <typename S, int N, typename Dev, typename Vec>
void track_substep(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, Mode mode, const Vec& y0, const Vec& y1, S h,
                   S t1, bool floors = true) {
  constexpr int NX = Model<S, N, Dev>::kNx;
  const auto z0 = y0.template head<NX>();
  const auto z1 = y1.template head<NX>();
  detail::update_top_peak_cubic(d, m.top_x(z0), m.top_v(z0), m.top_x(z1), m.top_v(z1), h, t1);
  if (floors && m.loop.floor_peaks)
    detail::update_peaks<S, N>(m.floor_x(z0), m.floor_v(z0), m.floor_x(z1), m.floor_v(z1), h, d.peak_x,
                               d.peak_drift);
  if (in_contact(mode)) {
    const S r = y1(NX) - m.dev_x(z1);
    const S dl = mode == Mode::kContactLeft ? overlap_left<S>(m.dev, r) : overlap_right<S>(m.dev, r);
    if (dl > d.contact_depth) d.contact_depth = dl;
    if (dl > d.max_overlap) d.max_overlap = dl;
  }
}

namespace detail {

// What the contact-mode transitions (take_event, contact_mode.hpp) do to a
// sub-stepper's state y: impacts of the instantaneous law, q at a contact's
// start, the contact counted at its end. A contact ends where q reaches zero
// if the walls overlap by no more than end_tol there (else q goes back on the
// overlap and the contact goes on).
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
struct EventAct {
  const Model<S, N, Dev>& m;
  Data<S, N, Dev>& d;
  Stepper& st;
  Vec& y;
  S end_tol;

  // Newton's law between the particle and the floor mass (Eq. 4).
  Impact impact(int side) {
    if constexpr (Dev::kImpulsive) {
      constexpr int NX = Model<S, N, Dev>::kNx;
      using VecX = typename Model<S, N, Dev>::VecX;
      const auto& dm = m.dev;
      const S rd = st.rel_vel(y);
      const S v_app = side < 0 ? -rd : rd;
      if (v_app <= S(0)) return Impact::kNone;
      S push, unused;  // the force that would hold the particle on the wall
      const Mode before = st.mode;
      st.mode = riding_at(side);
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
      return plastic ? Impact::kPlastic : Impact::kRebound;
    } else {
      (void)side;
      return Impact::kNone;
    }
  }

  // Riding wall `side` (the mode already set), the wall would have to pull.
  bool pulls(int side) const {
    S fp, loss;
    st.force(y, &fp, &loss);
    return (side < 0 && fp < S(0)) || (side > 0 && fp > S(0));
  }

  // q from the overlap with wall `side`; the contact's depth from zero.
  void begin_contact(int side) {
    const auto& dm = m.dev;
    const S dl = side < 0 ? overlap_left<S>(dm, st.rel_pos(y)) : overlap_right<S>(dm, st.rel_pos(y));
    y(Stepper::kQ) = std::sqrt(std::sqrt(std::fmax(dl, S(0))));
    d.contact_depth = S(0);
  }

  // q reached zero: the contact ends (counted if deep enough), unless the
  // walls still overlap (q and the overlap drifted apart): then q goes back
  // on the overlap.
  bool end_contact() {
    const auto& dm = m.dev;
    const S r = st.rel_pos(y);
    const S dl = st.mode == Mode::kContactLeft ? overlap_left<S>(dm, r) : overlap_right<S>(dm, r);
    if (dl > end_tol) {
      y(Stepper::kQ) = std::sqrt(std::sqrt(dl));
      return false;
    }
    if (d.contact_depth > m.dev.count_depth) ++d.count.contacts;
    return true;
  }
};

}  // namespace detail

// What happens at a located event (side: -1 left wall, +1 right wall): it is
// counted, and the contact-mode transition takes place with the
// sub-stepper's actions (detail::EventAct). Out of line: a rare path that
// both sub-steppers call from several places.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
VINES_NOINLINE void apply_event(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, Stepper& st, Vec& y, int side, S end_tol) {
#ifdef VINES_TRACE
  std::printf("event t=%.6f mode=%d side=%d r=%.6e rd=%.6e depth=%.3e\n", d.time(m), (int)st.mode, side,
              (double)st.rel_pos(y), (double)st.rel_vel(y), (double)d.contact_depth);
#endif
  ++d.count.events;
  detail::EventAct<S, N, Dev, Stepper, Vec> act{m, d, st, y, end_tol};
  take_event(st.mode, side, Dev::kImpulsive, act);
}

namespace detail {

// The relative tolerance of contacts that the scalar can honour.
template <typename S, int N, typename Dev>
S contact_rtol(const Model<S, N, Dev>& m) {
  return m.contact_rtol;
}

// An event due before any time passes (due_event), applied (apply_event):
// its wall side, 0 if none.
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
int apply_due_event(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, Stepper& st, Vec& y, S end_tol) {
  const int due = due_event(m, st, y);
  if (due != 0) apply_event(m, d, st, y, due, end_tol);
  return due;
}

// In a contact, q^4 and the overlap drift apart (most over a long, resting
// contact): q is put back on the overlap once they differ by more than tol.
// True if it was (the state's derivative is then stale).
template <typename S, int N, typename Dev, typename Stepper, typename Vec>
bool resync_q(const Model<S, N, Dev>& m, const Stepper& st, Vec& y, S tol) {
  constexpr int kQ = Stepper::kQ;
  const S r = st.rel_pos(y);
  const S dl = numeric::max_of(
      st.mode == Mode::kContactLeft ? overlap_left<S>(m.dev, r) : overlap_right<S>(m.dev, r), S(0));
  const S q2 = y(kQ) * y(kQ);
  if (!(std::fabs(q2 * q2 - dl) > tol)) return false;
  y(kQ) = std::sqrt(std::sqrt(dl));
  return true;
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
  d.ledger.contact.add(y(NX + 2));
  d.ledger.input.add(y(NX + 3));
  d.ledger.damping.add(y(NX + 4));
  d.ee_sum.add(y(NX + 5));
  S fp, loss;
  st.force(y, &fp, &loss);
  d.contact_force = fp;
}

}  // namespace detail

}  // namespace vines
