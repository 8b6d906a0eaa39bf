// One sensor step of the VI NES building in fixed point (issue 34,
// docs/fixed_point.md): the split scheme of substep_split.hpp on the model
// of fixed/vines_model.hpp, every operation Fixed's or Gain's, so the same
// bits on every core. The stages:
//   1. the free motion: the frame's exact step in the modes' units, the
//      particle's exact flight;
//   2. the contact going on, or the first touch of the free relative motion
//      on its cubic (in units of L over a step of length 1);
//   3. the free relative acceleration toward the wall as a Taylor cubic
//      from the modes' derivatives (each in its mode's own unit), and the
//      overlap's equation (split/forced_contact.hpp) in the contact's units;
//   4. the step's end: the modes and the particle moved by the force's
//      moments; a contact still on takes q back from the overlap;
//   5. E_e and the top floor's peak (fixed_frame_close, fixed/frame.hpp).
// Every saturation is counted (numeric::fixed_saturations()); a capped
// contact integration too (capped).
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "vines/fixed/ledger.hpp"
#include "vines/fixed/vines_model.hpp"
#include "vines/numeric/fixed_math.hpp"
#include "vines/numeric/hermite.hpp"
#include "vines/split/contact_step.hpp"
#include "vines/split/forced_contact.hpp"

namespace vines::fixed {

template <typename M>
struct FixedVinesData {
  using Q = typename M::Q;
  FixedFrameData<typename M::Frame> frame;  // the modes, the top floor's peak, E_e
  Q s = Q(0), sd = Q(0);  // the particle, in L and Vp
  int side = 0;           // the wall in contact: -1 left, +1 right, 0 none
  Q overlap = Q(0);       // the contact's overlap [L] while one goes on
  Q depth = Q(0);         // the deepest overlap of the contact going on or last [D]
  Q max_depth = Q(0);     // of the whole run
  // Contacts counted, events (starts and ends), capped integrations, sensor
  // steps with a contact in them, Runge-Kutta steps in all and in the worst.
  std::uint32_t contacts = 0, events = 0, capped = 0, careful = 0, contact_steps = 0, max_contact_steps = 0;
  numeric::Wide<kLedgerBits> lost;  // the energy lost in contacts [m V^2] (fixed/ledger.hpp)
};

// The state at rest with the particle at its start moving at v0 [Vp] and
// the first sample a0 [sa].
template <typename M>
void fixed_vines_init(const M& m, FixedVinesData<M>& d, typename M::Q v0, typename M::Q a0) {
  d = FixedVinesData<M>{};
  fixed_frame_init(m.frame, d.frame, a0);
  d.sd = v0;
}

// One sensor step to the sample a1 [sa].
template <typename M>
void fixed_vines_step(const M& m, FixedVinesData<M>& d, typename M::Q a1) {
  using Q = typename M::Q;
  using VecX = typename M::VecX;
  using VecP = typename M::VecP;
  constexpr int P = M::kP, K = M::kMoments;
  const Q a0 = d.frame.a_prev;
  d.frame.a_prev = a1;
  ++d.frame.steps;

  // 1. The free motion.
  const VecX z0 = d.frame.z;
  VecX z = z0;
  m.frame.lti.step(z, a0, a1);
  const Q xf0 = gain_dot<Q>(m.dev_x, z0.template head<P>());
  const Q vf0 = gain_dot<Q>(m.dev_v, z0.template tail<P>());
  const Q xf1 = gain_dot<Q>(m.dev_x, z.template head<P>());
  const Q vf1 = gain_dot<Q>(m.dev_v, z.template tail<P>());
  Q s = d.s + d.sd * m.fly_v - a0 * m.fly_a0 - a1 * m.fly_a1;
  Q sd = d.sd - (a0 + a1) * m.fly_dv;

  // 2. The contact going on, or the first touch.
  const Q r0 = d.s - xf0, rd0 = d.sd - vf0, r1 = s - xf1, rd1 = sd - vf1;
  // Where the contact starts: its side, theta (in the step), its overlap
  // [L] and its approach rate, u_src u_gain [V].
  int side = d.side;
  Q theta = Q(0), overlap0 = d.overlap, u_src = Q(0);
  numeric::Gain u_gain = m.to_speed;
  if (side != 0) {
    u_src = Q(side) * rd0;
  } else {
    for (int sg = -1; sg <= 1 && !(side != 0 && theta == Q(0)); sg += 2) {
      const Q g0 = sg < 0 ? m.wall_left - r0 : r0 - m.wall_right;
      const Q g1 = sg < 0 ? m.wall_left - r1 : r1 - m.wall_right;
      if (g0 > m.event_tol) {  // past the wall already (a contact that starts as another ended)
        side = sg;
        theta = Q(0);
        overlap0 = g0;
        u_src = Q(sg) * rd0;
        u_gain = m.to_speed;
        continue;
      }
      // The contact starts where the overlap passes event_tol (there q > 0
      // and the overlap's equation in w moves even from a grazing touch),
      // found by bisection to 2^-28 of the step (no quotient to saturate).
      const numeric::Cubic<Q> c{g0 - m.event_tol, Q(sg) * rd0 * m.fly_v, g1 - m.event_tol, Q(sg) * rd1 * m.fly_v,
                                Q(1)};
      if (!(c.max_value() > Q(0))) continue;
      const Q th = numeric::PowerCubic<Q>(c).first_upcrossing(24);
      if (side == 0 || th < theta) {
        side = sg;
        theta = th;
        overlap0 = m.event_tol;
        const Q slope = c.slope(th);
        u_src = slope > Q(0) ? slope : Q(0);
        u_gain = m.slope_to_speed;
      }
    }
  }
  if (side == 0) {
    d.frame.z = z;
    d.s = s;
    d.sd = sd;
  } else {
    // 3. The overlap's equation: g(t) from the modes' derivatives.
    const Q sg = Q(side);
    const VecP D0 = z0.template head<P>(), D1 = z0.template tail<P>();
    VecP D2, D3, D4, D5;
    const Q da = a1 - a0;
    for (int j = 0; j < P; ++j) {
      const std::size_t i = static_cast<std::size_t>(j);
      D2(j) = m.dk(j) * D0(j) + m.dc(j) * D1(j) + a0 * m.dg0[i];
      D3(j) = m.dk(j) * D1(j) + m.dc(j) * D2(j) + da * m.dg1[i];
      D4(j) = m.dk(j) * D2(j) + m.dc(j) * D3(j);
      D5(j) = m.dk(j) * D3(j) + m.dc(j) * D4(j);
    }
    // The contact's units: shrunk n times for a shallow contact (its scale
    // q_e below 0.4, from its start and the largest pressing of the cubic
    // over the step), so that the overlap's equation runs at O(1) values:
    // q_e ends in [0.4, 0.8), leaving room for a contact deeper than the
    // step's start predicts (at q = 1 the overlap's rate du/dw = 4 q^3 F m /
    // m* reaches Q3.28's 8 in an elastic impact at V). The cubic's terms are
    // summed 64 bits wide in each unit (the ground's term against the
    // modes'), not shifted from the first: a riding contact's are small
    // differences of large ones.
    auto taylor = [&](ContactCoupling<Q, K, numeric::Gain>& cc, int shift) {
      cc.g[0] = -(sg * gain_dot<Q>(m.gd[0], D2, shift, a0, m.ga));
      cc.g[1] = -(sg * gain_dot<Q>(m.gd[1], D3, shift, da, m.ga));
      cc.g[2] = -(sg * gain_dot<Q>(m.gd[2], D4, shift));
      cc.g[3] = -(sg * gain_dot<Q>(m.gd[3], D5, shift));
    };
    ContactCoupling<Q, K, numeric::Gain> c = m.coupling[0];
    taylor(c, 0);
    // The scale shrinks with the units, by 2^n exactly (the Hertz force's
    // similarity): the Runge-Kutta step follows from it.
    int n = 0;
    const Q q0 = numeric::sqrt(numeric::sqrt(overlap0 * m.to_overlap)), u0 = u_src * u_gain;
    Q q_e = contact_step(q0, u0, g_bound(c), m.m_star_c, m.q_floor, m.dw_unit, m.dw_max).q_e;
    while (n + 1 < M::kShrinks && q_e < Q(0.4)) {
      q_e = q_e * Q(2);
      ++n;
    }
    if (n > 0) {
      c = m.coupling[n];
      taylor(c, 6 * n);
    }
    ContactState<Q, K> y0;
    y0.setConstant(Q(0));
    y0(0) = numeric::sqrt(numeric::sqrt(overlap0 * m.to_overlap.shifted(4 * n)));
    y0(1) = u_src * u_gain.shifted(5 * n);
    y0(2) = theta * c.h;
    const ContactStep<Q> rule = step_of_scale(q_e, m.dw_unit, m.dw_max);
    const ForcedContact<Q, K> fc = forced_contact(m.law[n], c, y0, rule.dw, rule.q_e, m.max_steps);
    if (theta > Q(0) || d.side == 0) {
      ++d.events;
      d.depth = Q(0);
    }
    ++d.careful;
    d.contact_steps += static_cast<std::uint32_t>(fc.steps);
    if (static_cast<std::uint32_t>(fc.steps) > d.max_contact_steps) d.max_contact_steps = fc.steps;
    if (fc.capped) ++d.capped;
    d.lost += numeric::Wide<kLedgerBits>::from_raw(  // y's unit m V^2 2^-10n, to 40 bits
        wide_product(fc.y(K + 3), numeric::Gain::pow2(kLedgerBits - Q::kFractionBits - 10 * n)));

    // 4. The step's end.
    // Each mode takes its moments' terms summed 64 bits wide, rounded and
    // saturated once.
    const int back = -5 * n;  // the moments' unit m V 2^-5n tau^k
    using W = numeric::Wide<Q::kFractionBits>;
    Q mu[K];
    for (int k = 0; k < K; ++k) mu[k] = sg * fc.y(3 + k);
    for (int j = 0; j < P; ++j) {
      const std::size_t i = static_cast<std::size_t>(j);
      W dx = W::from_raw(0), dv = W::from_raw(0);
      for (int k = 0; k < K; ++k) {
        dx += W::from_raw(wide_product(mu[k], m.mom_x[k][i].shifted(back)));
        dv += W::from_raw(wide_product(mu[k], m.mom_v[k][i].shifted(back)));
      }
      z(j) += dx.template to_fixed<Q::kFractionBits>();
      z(P + j) += dv.template to_fixed<Q::kFractionBits>();
    }
    sd -= sg * fc.y(3) * m.mu_v.shifted(back);
    s -= sg * fc.y(4) * m.mu_x.shifted(back);
    const Q q_max = fc.q_max * numeric::Gain::pow2(-n), q2 = q_max * q_max, q4 = q2 * q2;
    if (q4 > d.depth) d.depth = q4;
    const Q r_end = s - gain_dot<Q>(m.dev_x, z.template head<P>());
    const Q overlap = side < 0 ? m.wall_left - r_end : r_end - m.wall_right;
    if (!fc.ended && overlap > Q(0)) {
      d.side = side;
      d.overlap = overlap;
      const Q o = overlap * m.to_overlap;
      if (o > d.depth) d.depth = o;
    } else {
      ++d.events;
      if (d.depth > m.count_depth) ++d.contacts;
      d.side = 0;
      d.overlap = Q(0);
    }
    if (d.depth > d.max_depth) d.max_depth = d.depth;
    d.frame.z = z;
    d.s = s;
    d.sd = sd;
  }

  // 5. E_e and the top floor's peak.
  fixed_frame_close(m.frame, d.frame);
}

}  // namespace vines::fixed
