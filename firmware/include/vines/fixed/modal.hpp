// The modal exact step (ModalLti, the linear frame propagation) in fixed
// point. Each mode j is carried in scaled units, q~ = q / sq_j,
// q~' = q' / (w_j sq_j), a~ = a_g / sa, so that every state value and every
// coefficient is O(1) or smaller; ModalLti<Fixed<F>, P>::step then runs
// unchanged on the scaled coefficients.
//
// Choosing the scales: sq_j = c * gamma_j * sa / w_j^2 (c times the static
// response of mode j to a ground acceleration sa); the state must stay below
// 2^(31-F) (8 for Q3.28), so c >= the largest dynamic amplification the
// record can cause (2 % damping: at most 1 / (2 zeta) = 25 at resonance;
// El Centro excites the frame's first mode about 5x). Saturation is counted
// (fixed_saturations()), never silent wrap-around.
//
// Fit for: the linear frame and its exact step between samples (the bare
// frame, and the free-flight steps of the VI NES, whose particle moves as a
// ballistic polynomial). Not fit for: contact (the Hertz force spans ~10
// decades between first touch and the deepest overlap, and delta^(3/2)
// needs roots), the event location, and the energy integrals (quadratic in
// the state: they need 64-bit accumulation). tests/test_fixed.cpp measures
// the error against double on El Centro.
#pragma once

#include <cmath>

#include "vines/model/lti.hpp"
#include "vines/numeric/fixed.hpp"

namespace vines::numeric {

template <int P>
struct ModalScales {
  Eigen::Matrix<double, P, 1> q;  // sq_j
  Eigen::Matrix<double, P, 1> v;  // sv_j = w_j sq_j
  double a = 1.0;                 // sa
};

// Scales from the modal data: sq_j = c * |gamma_j| * sa / w_j^2.
template <int P>
ModalScales<P> modal_scales(const Eigen::Matrix<double, P, 1>& omega, const Eigen::Matrix<double, P, 1>& gamma,
                            double sa, double c) {
  ModalScales<P> s;
  s.a = sa;
  for (int j = 0; j < P; ++j) {
    s.q(j) = c * std::fabs(gamma(j)) * sa / (omega(j) * omega(j));
    s.v(j) = omega(j) * s.q(j);
  }
  return s;
}

// The double step's coefficients in scaled units, in Q(31-F).F, for the N
// modes of the scales; padding modes of the step (j >= N, see Layout) get
// zero coefficients and stay at zero.
template <int F, int N, int P>
ModalLti<Fixed<F>, P> scaled_modal(const ModalLti<double, P>& l, const ModalScales<N>& s) {
  static_assert(N <= P, "more scaled modes than the step has");
  ModalLti<Fixed<F>, P> out;
  using V = Eigen::Matrix<double, P, 1>;
  V sq = V::Ones(), sv = V::Ones(), keep = V::Zero();
  sq.template head<N>() = s.q;
  sv.template head<N>() = s.v;
  keep.template head<N>().setOnes();
  auto put = [&keep](Eigen::Matrix<Fixed<F>, P, 1>& dst, const V& src) {
    dst = src.cwiseProduct(keep).template cast<Fixed<F>>();
  };
  put(out.p11, l.p11);
  put(out.p12, l.p12.cwiseProduct(sv).cwiseQuotient(sq));
  put(out.p21, l.p21.cwiseProduct(sq).cwiseQuotient(sv));
  put(out.p22, l.p22);
  put(out.gx0, (l.gx0 * s.a).cwiseQuotient(sq));
  put(out.gx1, (l.gx1 * s.a).cwiseQuotient(sq));
  put(out.gv0, (l.gv0 * s.a).cwiseQuotient(sv));
  put(out.gv1, (l.gv1 * s.a).cwiseQuotient(sv));
  // Continuous-time coefficients (sub-stepping): not carried in fixed point.
  for (auto* v : {&out.ak, &out.ac, &out.bgv, &out.bfv}) v->setConstant(Fixed<F>(0));
  return out;
}

}  // namespace vines::numeric
