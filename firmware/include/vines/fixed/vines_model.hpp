// The VI NES building in fixed point (issue 34, docs/fixed_point.md): the
// model the fixed-point split step (fixed/vines_step.hpp) runs on, every
// value in Q(31-F).F in a unit of its own, and every factor between units a
// numeric::Gain (any magnitude, one product and a shift). Built once, in
// double, from the double model (build_fixed_vines); the step itself has no
// double in it.
//
// Units (s: the particle's displacement from where it starts, r = s - x_f
// its position against the device floor; sa, amp, V the scales given; the
// modes, a_g, the top floor and E_e: fixed/frame.hpp):
//   a mode's k-th derivative  w_j^k sq_j
//   s, r, walls  L = sum_j |phi_dev,j| sq_j / 8 + the larger wall's distance
//                (s in range while every |q_j / sq_j| < 1)
//   s', r'       Vp = sum_j |phi_dev,j| w_j sq_j + V
//   a contact    fixed/contact_coupling.hpp (D, V, T = D / V, m the
//                particle's mass; the moments' arm in the sensor step h);
//                a shallow one (its depth scale q_e below 0.4 D^{1/4}) in
//                the units of an impact 2^-5n times as fast (D 2^-4n,
//                V 2^-5n, T 2^n: the Hertz force's own similarity, so q_e
//                is O(1) again and the law's coefficients change by powers
//                of two), n < kShrinks
#pragma once

#include <array>
#include <cmath>

#include <Eigen/Core>

#include "vines/fixed/contact_coupling.hpp"
#include "vines/fixed/frame.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/fixed_gain.hpp"
#include "vines/split/force_moments.hpp"
#include "vines/step/substep_split.hpp"

namespace vines::fixed {

// The force's moments the fixed-point step carries: four, not the double
// split's six (substep_split.hpp): the two more change El Centro's peaks by
// 1e-7 and E_r by 0.07 points in Q3.28 (tests/test_fixed_vines.cpp), below
// its resolution at the record's scale, and cost a third of each
// Runge-Kutta step on a Cortex-M3 (docs/fixed_point.md).
inline constexpr int kFixedMoments = 4;

// The scales a fixed-point model is built for: sa bounds the record's
// ground acceleration [m/s^2], amp the modes' dynamic amplification, V the
// contacts' approach speed [m/s].
struct FixedScales {
  double sa = 0, amp = 10, v_contact = 0;
};

template <int F, int P, template <typename> class Kernel, int K>
struct FixedVines {
  using Q = numeric::Fixed<F>;
  using G = numeric::Gain;
  using VecP = Eigen::Matrix<Q, P, 1>;
  using VecX = Eigen::Matrix<Q, 2 * P, 1>;
  using GainP = std::array<G, P>;
  static constexpr int kP = P, kMoments = K, kShrinks = 6;

  using Frame = FixedFrame<F, P>;

  Frame frame;                   // the modes, the top floor, E_e
  // In double, for reading results back and for reports.
  double length = 0, speed = 0;  // L, Vp [m, m/s]
  CouplingUnits cu;

  GainP dev_x, dev_v;            // x_f / L, v_f / Vp from the modes
  // The particle's free flight: s1 = s + s' fly_v - a0 fly_a0 - a1 fly_a1,
  // s1' = s' - (a0 + a1) fly_dv.
  G fly_v, fly_a0, fly_a1, fly_dv;
  Q wall_left, wall_right;       // in L
  Q event_tol;                   // a contact starts where the overlap [L] passes this (rounding makes smaller ones)
  // The modes' derivatives 2..5 from 0 and 1: D_{k+2} = dk D_k + dc D_{k+1}
  // + (a0 g0, (a1 - a0) g1 for k = 0, 1).
  VecP dk, dc;
  GainP dg0, dg1;
  // g(t)'s Taylor coefficients in powers of t / h, in the contact's units
  // (split/forced_contact.hpp): G_k = -(ground term) - sum_j gd[k]_j
  // D_{k+2,j}; ground terms a0 ga (k = 0), (a1 - a0) ga (k = 1). Shrunk n
  // times, every one scales by 2^6n.
  GainP gd[4];
  G ga;
  // The coupling's constants (g is the step's) and the law, in the
  // contact's units shrunk n times.
  ContactCoupling<Q, K, G> coupling[kShrinks];
  Kernel<Q> law[kShrinks];
  // From the contact back: the modes (A^k bf mu_k per mode, position and
  // velocity), the particle (s' -= mu_0 mu_v, s -= mu_1 mu_x).
  GainP mom_x[K], mom_v[K];
  G mu_v, mu_x;
  // Into the contact: a position in L to an overlap in D, a speed in Vp to V,
  // and a slope of the start's cubic (L per step) to V.
  G to_overlap, to_speed, slope_to_speed;
  // The Runge-Kutta step's rule (split/contact_step.hpp) in the contact's units.
  Q m_star_c, q_floor, dw_unit, dw_max;
  int max_steps = 0;
  Q count_depth;                   // overlap [D] a contact must pass to count
};

// The fixed-point model of the double model m (a VI NES on a modal frame).
template <int F, int K, typename Law, int N, typename Dev>
FixedVines<F, N, Law::template Kernel, K> build_fixed_vines(const Model<double, N, Dev>& m,
                                                           const FixedScales& sc) {
  constexpr int P = N;  // the real modes (build_fixed_frame)
  using Out = FixedVines<F, P, Law::template Kernel, K>;
  using Q = typename Out::Q;
  using G = numeric::Gain;
  using V = Eigen::Matrix<double, P, 1>;
  const auto& l = m.lti;
  const auto& dm = m.dev;
  Out o;
  o.frame = build_fixed_frame<F>(m, sc.sa, sc.amp);
  const V sq = o.frame.sq, sv = o.frame.sv, w = sv.cwiseQuotient(sq);
  const V dev = m.rows.dev.template head<N>();
  o.length = dev.cwiseAbs().dot(sq) / 8.0 + std::fmax(std::fabs(dm.wall_left), std::fabs(dm.wall_right));
  o.speed = dev.cwiseAbs().dot(sv) + sc.v_contact;
  const double L = o.length, Vp = o.speed, h = m.h;
  for (int j = 0; j < P; ++j) {
    o.dev_x[j] = G(m.rows.dev(j) * sq(j) / L);
    o.dev_v[j] = G(m.rows.dev(j) * sv(j) / Vp);
  }
  o.fly_v = G(Vp * h / L);
  o.fly_a0 = G(static_cast<double>(dm.ff_a0) * sc.sa / L);
  o.fly_a1 = G(static_cast<double>(dm.ff_a1) * sc.sa / L);
  o.fly_dv = G(static_cast<double>(dm.ff_v) * sc.sa / Vp);
  o.wall_left = Q(dm.wall_left / L);
  o.wall_right = Q(dm.wall_right / L);
  // 16 units of L (8.8e-8 m on the paper's building). The gap's rounding
  // reaches ~1e-7 m while the sphere rides with a wall, so it may chatter
  // there (a 5.8 N contact at 0.17 s of El Centro); 64 units stop that but
  // take the Cortex-M3's worst step past its budget (docs/fixed_point.md).
  o.event_tol = Q::from_raw(16);
  // The contact's units and the derivative chains.
  o.cu = {contact_units(dm.m, dm.c, sc.v_contact), h};
  const ContactUnits& u = o.cu.u;
  for (int j = 0; j < P; ++j) {
    const bool live = l.ak(j) != 0.0;
    o.dk(j) = Q(live ? l.ak(j) / (w(j) * w(j)) : 0.0);
    o.dc(j) = Q(live ? l.ac(j) / w(j) : 0.0);
    o.dg0[j] = G(live ? l.bgv(j) * sc.sa / (sq(j) * w(j) * w(j)) : 0.0);
    o.dg1[j] = G(live ? l.bgv(j) * sc.sa / (sq(j) * w(j) * w(j) * w(j) * h) : 0.0);
    double wt = w(j) * w(j) * u.t * u.t;  // w_j^(k+2) T^2 h^k / k!
    for (int k = 0; k < 4; ++k, wt *= w(j) * h / (k + 1))
      o.gd[k][j] = G(live ? m.rows.dev(j) * sq(j) * wt / u.d : 0.0);
  }
  o.ga = G(sc.sa * u.t * u.t / u.d);
  // The coupling's constants: split_coupling's on a state at rest.
  const auto fm = force_moments<K>(l);
  const ContactCoupling<double, K> c_si =
      vines::detail::split_coupling(m, fm, Model<double, N, Dev>::VecX::Zero().eval(), 0.0, 0.0, 1);
  for (int n = 0; n < Out::kShrinks; ++n) {
    const CouplingUnits shrunk{contact_units(dm.m, dm.c, std::ldexp(sc.v_contact, -5 * n)), h};
    o.coupling[n] = scaled_coupling<Q, G>(c_si, shrunk);
    o.law[n] = scaled_kernel<Q>(dm.law, shrunk.u);
  }
  double arm = u.m * u.v;  // m V h^k
  for (int k = 0; k < K; ++k, arm *= h)
    for (int j = 0; j < P; ++j) {
      o.mom_x[k][j] = G(fm.x[k](j) * arm / sq(j));
      o.mom_v[k][j] = G(fm.v[k](j) * arm / sv(j));
    }
  o.mu_v = G(u.v / Vp);
  o.mu_x = G(u.v * h / L);
  o.to_overlap = G(L / u.d);
  o.to_speed = G(Vp / u.v);
  o.slope_to_speed = G(L / (h * u.v));
  // The step rule: split/contact_step.hpp in the contact's units (the law's
  // elastic coefficient is 5/4 there).
  const double c_hat = static_cast<double>(scaled_kernel<double>(dm.law, u).c);
  const double inv_m_star_hat = c_si.inv_m_star * u.m;
  o.m_star_c = Q(1.0 / (inv_m_star_hat * c_hat));
  o.dw_unit = Q(1.0 / (m.loop.split_steps * std::sqrt(0.8 * c_hat * inv_m_star_hat)));
  o.dw_max = Q(1.0);
  o.q_floor = Q(std::sqrt(std::sqrt(1e-6)));  // the scale of an overlap of a millionth of D
  o.max_steps = kSplitCap * m.loop.split_steps;
  o.count_depth = Q(std::fmax(static_cast<double>(dm.count_depth), static_cast<double>(o.event_tol) * L) / u.d);
  return o;
}

}  // namespace vines::fixed
