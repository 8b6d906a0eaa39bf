// The frame in fixed point (issue 34, docs/fixed_point.md): the modal exact
// step in each mode's own units (fixed/modal.hpp), the top floor's
// peak and E_e, for the bare frame and under the VI NES
// (fixed/vines_model.hpp). Built once, in double, from the double model;
// the step has no double in it.
//
// Units (sa, amp the scales given):
//   mode j       q / sq_j, q' / (w_j sq_j), sq_j = amp |gamma_j| sa / w_j^2
//   a_g          sa
//   top floor    Lt = sum_j |phi_top,j| sq_j, its speed Vt = sum_j |phi_top,j| w_j sq_j
//   E_e          the sum over modes of (1/2) k_j sq_j^2 h
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "vines/fixed/ledger.hpp"
#include "vines/fixed/modal.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/fixed_gain.hpp"
#include "vines/numeric/fixed_math.hpp"

namespace vines::fixed {

template <int F, int P>
struct FixedFrame {
  using Q = numeric::Fixed<F>;
  using VecP = Eigen::Matrix<Q, P, 1>;
  using VecX = Eigen::Matrix<Q, 2 * P, 1>;
  using GainP = std::array<numeric::Gain, P>;
  static constexpr int kP = P;

  // In double, for reading results back and for reports.
  double h = 0, sa = 0, top_length = 0, top_speed = 0, ee_unit = 0;
  Eigen::Matrix<double, P, 1> sq, sv;  // each mode's position and velocity unit (1 for padding modes)

  ModalLti<Q, P> lti;  // the exact step in the modes' units
  GainP top_x, top_v;  // x_top / Lt, v_top / Vt from the modes
  GainP ee;            // a mode's strain energy times h, in E_e's unit
};

// The modal step's first N modes (the real ones: a build that pads the
// modes to its SIMD width, Layout::kLanes, pads past them).
template <int N, typename S, int P>
ModalLti<S, N> real_modes(const ModalLti<S, P>& l) {
  static_assert(N <= P, "more modes than the step has");
  ModalLti<S, N> o;
  o.p11 = l.p11.template head<N>();
  o.p12 = l.p12.template head<N>();
  o.p21 = l.p21.template head<N>();
  o.p22 = l.p22.template head<N>();
  o.gx0 = l.gx0.template head<N>();
  o.gx1 = l.gx1.template head<N>();
  o.gv0 = l.gv0.template head<N>();
  o.gv1 = l.gv1.template head<N>();
  o.ak = l.ak.template head<N>();
  o.ac = l.ac.template head<N>();
  o.bgv = l.bgv.template head<N>();
  o.bfv = l.bfv.template head<N>();
  return o;
}

// The fixed-point frame of the double model m (a modal one: no device or a
// VI NES), for ground accelerations up to sa [m/s^2] amplified up to amp.
// Its N real modes only, whatever the double model's padding: the fixed
// step runs mode by mode, and its layout is the same on every target (the
// fixed-point model image, fixed/image.hpp).
template <int F, int N, typename Dev>
FixedFrame<F, N> build_fixed_frame(const Model<double, N, Dev>& m, double sa, double amp) {
  constexpr int P = N;
  using G = numeric::Gain;
  const auto& l = m.lti;
  FixedFrame<F, P> o;
  o.h = m.h;
  o.sa = sa;
  o.sq.setOnes();
  o.sv.setOnes();
  numeric::ModalScales<P> ms;
  ms.a = sa;
  for (int j = 0; j < P; ++j) {
    if (l.ak(j) == 0.0) continue;  // a padding mode
    const double w = std::sqrt(-l.ak(j));
    o.sq(j) = amp * std::fabs(l.bgv(j)) * sa / (w * w);
    o.sv(j) = w * o.sq(j);
  }
  ms.q = o.sq;
  ms.v = o.sv;
  o.lti = real_modes<N>(numeric::scaled_modal<F, N>(l, ms));
  o.top_length = m.rows.top.template head<N>().cwiseAbs().dot(o.sq);
  o.top_speed = m.rows.top.template head<N>().cwiseAbs().dot(o.sv);
  o.ee_unit = 0;
  for (int j = 0; j < P; ++j) o.ee_unit += m.strain.qq(j) * o.sq(j) * o.sq(j) * m.h;
  for (int j = 0; j < P; ++j) {
    o.top_x[j] = G(m.rows.top(j) * o.sq(j) / o.top_length);
    o.top_v[j] = G(m.rows.top(j) * o.sv(j) / o.top_speed);
    o.ee[j] = G(m.strain.qq(j) * o.sq(j) * o.sq(j) * m.h / o.ee_unit);
  }
  return o;
}

template <typename Fr>
struct FixedFrameData {
  using Q = typename Fr::Q;
  typename Fr::VecX z = Fr::VecX::Constant(Q(0));  // the modes
  Q a_prev = Q(0);        // the last sample, in sa
  Q peak_top = Q(0);      // largest |x_top| at a step's end [Lt]
  Q peak_top_velocity = Q(0);  // largest |v_top| at a step's end [Vt]
  numeric::Wide<40> ee;   // E_e [ee_unit]
  std::uint32_t steps = 0, peak_step = 0;  // steps taken; the one that ended at the peak
  FixedLedgerData ledger;  // the energy ledger, when the node model keeps one (fixed/node_model.hpp)
};

// (x0 g0 + sum_j v_j g_j) 2^shift, summed 64 bits wide and saturated once
// (numeric::wide_product): the modes' terms of a floor's motion may cancel
// one another, and the ground's term x0 g0 theirs.
template <typename Q, std::size_t P, typename Z>
Q gain_dot(const std::array<numeric::Gain, P>& g, const Z& v, int shift = 0, Q x0 = Q(0),
           numeric::Gain g0 = numeric::Gain()) {
  using W = numeric::Wide<Q::kFractionBits>;
  W sum = W::from_raw(wide_product(x0, g0.shifted(shift)));
  for (std::size_t j = 0; j < P; ++j) sum += W::from_raw(wide_product(v(static_cast<int>(j)), g[j].shifted(shift)));
  return sum.template to_fixed<Q::kFractionBits>();
}

// At rest, the first sample a0 [sa].
template <typename Fr>
void fixed_frame_init(const Fr& /*fr*/, FixedFrameData<Fr>& d, typename Fr::Q a0) {
  d = FixedFrameData<Fr>{};
  d.a_prev = a0;
}

// A step's end: E_e (the strain energy at the end times h, in a 64-bit sum)
// and the top floor's peaks.
template <typename Fr>
void fixed_frame_close(const Fr& fr, FixedFrameData<Fr>& d) {
  using Q = typename Fr::Q;
  for (int j = 0; j < Fr::kP; ++j) d.ee.add_product(d.z(j), d.z(j) * fr.ee[static_cast<std::size_t>(j)]);
  const Q xt = abs(gain_dot<Q>(fr.top_x, d.z.template head<Fr::kP>()));
  if (xt > d.peak_top) {
    d.peak_top = xt;
    d.peak_step = d.steps;
  }
  const Q vt = abs(gain_dot<Q>(fr.top_v, d.z.template tail<Fr::kP>()));
  if (vt > d.peak_top_velocity) d.peak_top_velocity = vt;
}

// One sensor step of the bare frame to the sample a1 [sa].
template <typename Fr>
void fixed_frame_step(const Fr& fr, FixedFrameData<Fr>& d, typename Fr::Q a1) {
  fr.lti.step(d.z, d.a_prev, a1);
  d.a_prev = a1;
  ++d.steps;
  fixed_frame_close(fr, d);
}

}  // namespace vines::fixed
