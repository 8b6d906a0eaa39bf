// The split contact scheme (loop.contact_scheme = "split"; issue 34,
// docs/fixed_point.md): a sensor step in which the VI NES particle is in, or
// may come into, contact with a wall integrates one scalar equation, the
// overlap's, and moves everything else exactly:
//   1. the free motion over the step: the frame's exact step, the particle's
//      exact flight;
//   2. the contact: the one going on, or a start found on the cubic through
//      both ends of the free relative motion;
//   3. the overlap's equation (split/forced_contact.hpp) from there to the
//      contact's end or the step's end, in w (dt/dw = 4 q^3) by classic
//      Runge-Kutta: the free relative acceleration toward the wall a Taylor
//      cubic from the step's start, the device floor's response to the
//      force through its Markov parameters; it returns the force's moments
//      about the step's end, mu_k = int F(s) (h - s)^k / k! ds, and the
//      energy lost;
//   4. the step's end: the frame is the free step plus sum_k (A^k bf) mu_k
//      (split/force_moments.hpp), the particle its free flight less mu_1 / m
//      and mu_0 / m; a contact still on at the end takes q back from the
//      assembled overlap (its rate from the assembled velocities), one that
//      ended is counted; a contact that starts after another ended in the
//      same step starts at the next step, from its overlap;
//   5. the step integrals (E_e; the ledger's input and damping when asked
//      for) by 3-point Gauss quadrature on the cubic Hermite interpolant of
//      the state between the step's ends; the top floor's peak on its cubic.
// Runge-Kutta steps are sized by the contact's own depth scale (split_scale),
// so an impact takes about 2 loop.split_steps steps whatever its speed. Work
// of a step: at most kSplitCap loop.split_steps Runge-Kutta steps of a
// (kSplitMoments + 4)-state system (a cap hit ends the contact's integration
// early and is counted), plus a fixed number of passes over the modes. Only
// for laws with a finite contact duration (validate refuses an
// instantaneous one). docs/model.md section 7.9 has the measurements.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "vines/model/contact_mode.hpp"
#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/hermite.hpp"
#include "vines/numeric/minmax.hpp"
#include "vines/split/contact_step.hpp"
#include "vines/split/force_moments.hpp"
#include "vines/split/forced_contact.hpp"
#include "vines/step/events.hpp"
#include "vines/step/exact_step.hpp"
#include "vines/step/peaks.hpp"
#include "vines/step/substep_common.hpp"

namespace vines {

// The force's moments a split step carries (split/force_moments.hpp).
#ifndef VINES_SPLIT_MOMENTS
#define VINES_SPLIT_MOMENTS 6
#endif
inline constexpr int kSplitMoments = VINES_SPLIT_MOMENTS;

namespace detail {

// The overlap's coupling over the step toward wall `side` (-1 left, +1
// right): 1/m*, the device floor's Markov parameters M_n (the floor's part
// of the velocity entries of A^(n-1) bf; fm holds A^k bf for k < 4), and the
// free relative acceleration toward the wall as a Taylor cubic from the
// step's start, in powers of t [s] (the particle's is -a_g, linear; the floor's from z's
// derivatives).
template <typename S, int N, typename Dev, int K>
fixed::ContactCoupling<S, K> split_coupling(const Model<S, N, Dev>& m,
                                            const fixed::ForceMoments<S, Model<S, N, Dev>::kP, K>& fm,
                                            const typename Model<S, N, Dev>::VecX& z, S a0, S al, int side) {
  constexpr int P = Model<S, N, Dev>::kP;
  using ArrP = Eigen::Array<S, P, 1>;
  const auto& l = m.lti;
  const auto& dev = m.rows.dev;
  fixed::ContactCoupling<S, K> c;
  c.inv_m_star = m.dev.inv_m + dev.dot(fm.v[0]);
  for (int k = 1; k < K; ++k) c.markov[k - 1] = dev.dot(fm.v[k]);
  c.markov[K - 1] = dev.dot((l.ak.array() * fm.x[K - 1].array() + l.ac.array() * fm.v[K - 1].array()).matrix());
  c.h = m.period;
  // Derivatives 2..5 of the modal positions under a_g = a0 + al t.
  const ArrP q = z.template head<P>().array(), v = z.template tail<P>().array();
  const ArrP d2 = l.ak.array() * q + l.ac.array() * v + l.bgv.array() * a0;
  const ArrP d3 = l.ak.array() * v + l.ac.array() * d2 + l.bgv.array() * al;
  const ArrP d4 = l.ak.array() * d2 + l.ac.array() * d3;
  const ArrP d5 = l.ak.array() * d3 + l.ac.array() * d4;
  const S sg = S(side);
  c.g[0] = sg * (-a0 - dev.dot(d2.matrix()));
  c.g[1] = sg * (-al - dev.dot(d3.matrix()));
  c.g[2] = -sg * dev.dot(d4.matrix()) / S(2);
  c.g[3] = -sg * dev.dot(d5.matrix()) / S(6);
  return c;
}

// The Runge-Kutta step in w for a contact at q with overlap rate u under a
// free relative acceleration toward the wall of at most g
// (split/contact_step.hpp): about 2 loop.split_steps steps an impact,
// whatever its speed. A contact with neither energy nor pressing gets the
// scale of a thousandth of the model's typical one.
template <typename S, int N, typename Dev>
fixed::ContactStep<S> split_scale(const Model<S, N, Dev>& m, S q, S u, S g) {
  const auto& dm = m.dev;
  const S dw_unit = S(1) / (static_cast<S>(m.loop.split_steps) * std::sqrt(S(0.8) * dm.c / dm.m_star));
  return fixed::contact_step(q, u, std::fabs(g), dm.m_star / dm.c, S(1e-3) * dm.q_scale, dw_unit,
                             std::numeric_limits<S>::infinity());
}

// Where a free step (relative position r, rate rd at both ends) first
// touches a wall: the side (0: none), the time and the approach rate there,
// on the cubic through both ends. A particle already past a wall at the
// step's start is in contact from it.
template <typename S>
struct SplitStart {
  int side = 0;
  S t = S(0), q = S(0), u = S(0);
};

template <typename S, int N, typename Dev>
SplitStart<S> split_start(const Model<S, N, Dev>& m, S r0, S rd0, S r1, S rd1) {
  const auto& dm = m.dev;
  const S h = m.period;
  SplitStart<S> best;
  for (int side = -1; side <= 1; side += 2) {
    const S sg = S(side);
    const S g0 = side < 0 ? overlap_left<S>(dm, r0) : overlap_right<S>(dm, r0);
    const S g1 = side < 0 ? overlap_left<S>(dm, r1) : overlap_right<S>(dm, r1);
    if (g0 > S(0)) return {side, S(0), std::sqrt(std::sqrt(g0)), sg * rd0};
    const auto c = numeric::Cubic<S>::make(g0, sg * rd0, g1, sg * rd1, h);
    if (!(c.max_value() > S(0))) continue;
    const S th = polish_root<8>(c, c.first_upcrossing(20), S(0), S(1));
    const S t = th * h;
    if (best.side == 0 || t < best.t) best = {side, t, S(0), numeric::max_of(c.slope(th) / h, S(0))};
  }
  return best;
}

// E_e over the step, and the ledger's input and damping work when asked
// for, by 3-point Gauss quadrature on the cubic Hermite interpolants of the
// frame (z0, f0 -> z1, f1) and the particle's speed (sd0, acc0 -> sd1, acc1).
template <typename S, int N, typename Dev>
void split_integrals(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, const typename Model<S, N, Dev>::VecX& z0,
                     const typename Model<S, N, Dev>::VecX& f0, const typename Model<S, N, Dev>::VecX& z1,
                     const typename Model<S, N, Dev>::VecX& f1, S sd0, S acc0, S sd1, S acc1, S a0, S a1) {
  constexpr int P = Model<S, N, Dev>::kP;
  const S h = m.period;
  const S r = std::sqrt(S(0.15));
  const S nodes[3] = {S(0.5) - r, S(0.5), S(0.5) + r};
  const S weights[3] = {S(5) / S(18), S(8) / S(18), S(5) / S(18)};
  const auto sd = numeric::Cubic<S>::make(sd0, acc0, sd1, acc1, h);
  S ee = S(0), input = S(0), damping = S(0);
  for (int i = 0; i < 3; ++i) {
    const typename Model<S, N, Dev>::VecX z = numeric::hermite_point(z0, f0, z1, f1, h, nodes[i]);
    ee += weights[i] * m.strain.eval_positions(z.template head<P>());
    if (m.loop.energy_ledger) {
      const S a = a0 + nodes[i] * (a1 - a0);
      input += weights[i] * (m.input_power.eval(z, a) - a * m.dev.m * sd.value(nodes[i]));
      damping += weights[i] * m.damping_power.eval(z, a);
    }
  }
  d.ee_sum.add(ee * h);
  if (m.loop.energy_ledger) {
    d.ledger.input.add(input * h);
    d.ledger.damping.add(damping * h);
  }
}

// No contact after all: the free step (frame z1, readouts r, particle s1,
// sd1) committed as an exact step is (exact_step.hpp).
template <typename S, int N, typename Dev>
void commit_free_step(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, const typename Model<S, N, Dev>::VecX& z1,
                      const StepRead<S>& r, S s1, S sd1, S a0, S a1) {
  add_elastic_step(m, d, d.z, r, a0, a1);
  const S peak = top_peak_of_step(m, d.z, z1, a0, a1, d.xt, d.vt, r.xt, r.vt, d.peak_top);
  if (peak > d.peak_top) {
    d.peak_top = peak;
    d.peak_top_k = d.k;
    d.peak_top_dt = m.period;
  }
  keep_extras(m, d, z1, a0, a1, d.sd);
  d.z = z1;
  d.s = s1;
  d.sd = sd1;
}

}  // namespace detail

// One sensor step from the current state to the next sample a1 by the split
// scheme (see the top). Same state, counters and write-back as the other
// sub-steppers.
template <typename S, int N, typename Dev>
void substep_split(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a0, S a1) {
  using VecX = typename Model<S, N, Dev>::VecX;
  const auto& dm = m.dev;
  const S h = m.period, al = (a1 - a0) / h;
  ++d.count.careful_steps;

  // 1. The free motion over the step.
  const VecX z0 = d.z;
  VecX z1;
  const StepRead<S> read = detail::linear_step(m, z0, z1, a0, a1);
  S s1, sd1;
  free_flight(m, d.s, d.sd, a0, a1, &s1, &sd1);

  // 2. The contact going on, or the first touch of the free motion.
  detail::SplitStart<S> start;
  const S r0 = d.s - m.dev_x(z0), rd0 = d.sd - m.dev_v(z0);
  if (in_contact(d.mode)) {
    const int side = d.mode == Mode::kContactLeft ? -1 : 1;
    start = {side, S(0), d.q, S(side) * rd0};
  } else {
    start = detail::split_start(m, r0, rd0, s1 - read.xf, sd1 - read.vf);
  }

  if (start.side == 0) {
    detail::commit_free_step(m, d, z1, read, s1, sd1, a0, a1);
    return;
  }

  // 3. The overlap's equation from the contact's start.
  const S sg = S(start.side);
  constexpr int K = kSplitMoments;
  const auto fm = fixed::force_moments<K>(m.lti);
  const fixed::ContactCoupling<S, K> c = detail::split_coupling(m, fm, z0, a0, al, start.side);
  fixed::ContactState<S, K> y0 = fixed::ContactState<S, K>::Zero();
  y0(0) = start.q;
  y0(1) = start.u;
  y0(2) = start.t;
  const int cap = kSplitCap * m.loop.split_steps;
  const fixed::ContactStep<S> scale = detail::split_scale(m, start.q, start.u, fixed::g_bound(c));
  const fixed::ForcedContact<S, K> fc =
      fixed::forced_contact(dm.law, c, y0, scale.dw, scale.q_e, cap);
  S mu[K];
  for (int k = 0; k < K; ++k) mu[k] = fc.y(3 + k);
  if (start.t > S(0) || !in_contact(d.mode)) {
    ++d.count.events;
    d.contact_depth = S(0);
  }
  d.count.substeps += fc.steps;
  d.count.contact_substeps += fc.steps;
  if (fc.steps > d.count.max_substeps_in_step) d.count.max_substeps_in_step = fc.steps;
  if (fc.capped) ++d.count.cap_hits;

  // 4. The step's end: the frame and the particle moved by the force's moments.
  VecX z = z1;
  for (S& x : mu) x *= sg;
  fm.apply(z, mu);
  const S sd_end = sd1 - mu[0] * dm.inv_m;
  const S s_end = s1 - mu[1] * dm.inv_m;
  const S q4 = fc.q_max * fc.q_max * fc.q_max * fc.q_max;
  if (q4 > d.contact_depth) d.contact_depth = q4;
  const S r_end = s_end - m.dev_x(z);
  const S overlap = start.side < 0 ? overlap_left<S>(dm, r_end) : overlap_right<S>(dm, r_end);
  S f_end = S(0);  // the law's force at the step's end
  if (!fc.ended && overlap > S(0)) {
    d.mode = start.side < 0 ? Mode::kContactLeft : Mode::kContactRight;
    d.q = std::sqrt(std::sqrt(overlap));
    f_end = dm.law.regular(d.q, sg * (sd_end - m.dev_v(z))).total();
    if (overlap > d.contact_depth) d.contact_depth = overlap;
  } else {
    ++d.count.events;
    if (d.contact_depth > dm.count_depth) ++d.count.contacts;
    d.mode = Mode::kFree;
    d.q = S(0);
  }
  if (d.contact_depth > d.max_overlap) d.max_overlap = d.contact_depth;

  // 5. The step integrals, the peaks.
  S f_start = S(0);
  if (start.t == S(0)) f_start = dm.law.regular(start.q, start.u).total();
  const VecX f0 = m.lti.derivative(z0, a0, sg * f_start), f1 = m.lti.derivative(z, a1, sg * f_end);
  detail::split_integrals(m, d, z0, f0, z, f1, d.sd, -a0 - sg * f_start * dm.inv_m, sd_end,
                          -a1 - sg * f_end * dm.inv_m, a0, a1);
  if (m.loop.energy_ledger) d.ledger.contact.add(fc.y(K + 3));
  detail::update_top_peak_cubic(d, m.top_x(z0), m.top_v(z0), m.top_x(z), m.top_v(z), h, h);
  if (m.loop.floor_peaks)
    detail::update_peaks<S, N>(m.floor_x(z0), m.floor_v(z0), m.floor_x(z), m.floor_v(z), h, d.peak_x,
                               d.peak_drift);
  d.z = z;
  d.s = s_end;
  d.sd = sd_end;
  d.contact_force = -sg * f_end;
}

}  // namespace vines
