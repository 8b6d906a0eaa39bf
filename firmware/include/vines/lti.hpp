// The linear part of the model (frame, plus a TMD when there is one) as
//   z' = A z + bg a_g(t) + bf F(t),
// with A block-diagonal in blocks of size B (B = 2: one block per mode in
// modal coordinates; B = NX: one dense block). Over a sensor step the ground
// acceleration is linear between two samples and F = 0, so the step is exact:
//   z_{k+1} = Phi z_k + Gam [a_k, a_{k+1}]^T   (first-order-hold discretisation).
// Quadratic integrals of the state over a step (strain energy, damping
// dissipation, input work) are exact too (Van Loan 1978). Everything is
// computed once in double, then stored in the loop's scalar S.
#pragma once

#include <Eigen/Core>

#include "vines/numeric/expm.hpp"

namespace vines {

// Continuous-time description, in double, handed to the builders below.
template <int NX>
struct LtiSpec {
  Eigen::Matrix<double, NX, NX> a;  // must be block-diagonal in the chosen B
  Eigen::Matrix<double, NX, 1> bg;  // ground acceleration input
  Eigen::Matrix<double, NX, 1> bf;  // device force input (on the device floor)
};

template <typename S, int NX, int B>
struct Lti {
  static_assert(NX % B == 0, "blocks must tile the state");
  static constexpr int NB = NX / B;
  using VecX = Eigen::Matrix<S, NX, 1>;
  using Block = Eigen::Matrix<S, B, B>;
  using Col = Eigen::Matrix<S, B, 1>;

  Block phi[NB];                     // exact step
  Eigen::Matrix<S, B, 2> gam[NB];    // FOH input gains for (a_k, a_{k+1})
  Block a[NB];                       // continuous time, for sub-stepping
  Col bg[NB];
  Col bf[NB];

  // One exact sensor step with no device force.
  void step(VecX& z, S a0, S a1) const {
    for (int b = 0; b < NB; ++b) {
      const Col zb = z.template segment<B>(b * B);
      z.template segment<B>(b * B) = phi[b] * zb + gam[b].col(0) * a0 + gam[b].col(1) * a1;
    }
  }

  // z' for sub-stepping: ground acceleration a, device force f.
  VecX derivative(const VecX& z, S ag, S f) const {
    VecX d;
    for (int b = 0; b < NB; ++b)
      d.template segment<B>(b * B) =
          a[b] * z.template segment<B>(b * B) + bg[b] * ag + bf[b] * f;
    return d;
  }
};

// Exact quadratic integral over one step: integral_0^h xi(s)^T Q xi(s) ds with
// xi = [z; a_g], as a quadratic form in (z_k, a_k, a_{k+1}), block by block.
template <typename S, int NX, int B>
struct QuadIntegral {
  static constexpr int NB = NX / B;
  Eigen::Matrix<S, B + 2, B + 2> w[NB];

  S eval(const Eigen::Matrix<S, NX, 1>& z, S a0, S a1) const {
    S sum = S(0);
    for (int b = 0; b < NB; ++b) {
      Eigen::Matrix<S, B + 2, 1> xi;
      xi << z.template segment<B>(b * B), a0, a1;
      sum += xi.dot(w[b] * xi);
    }
    return sum;
  }
};

// Instantaneous quadratic form [z; a]^T Q [z; a] with the same block
// structure: a per-block matrix and a per-block coupling with a.
template <typename S, int NX, int B>
struct BlockForm {
  static constexpr int NB = NX / B;
  Eigen::Matrix<S, B, B> zz[NB];
  Eigen::Matrix<S, B, 1> za[NB];
  S aa = S(0);

  S eval(const Eigen::Matrix<S, NX, 1>& z, S ag) const {
    S sum = aa * ag * ag;
    for (int b = 0; b < NB; ++b) {
      const Eigen::Matrix<S, B, 1> zb = z.template segment<B>(b * B);
      sum += zb.dot(zz[b] * zb) + S(2) * ag * za[b].dot(zb);
    }
    return sum;
  }
};

template <typename S, int NX, int B>
BlockForm<S, NX, B> block_form(const Eigen::Matrix<double, NX + 1, NX + 1>& q) {
  BlockForm<S, NX, B> out;
  for (int b = 0; b < NX / B; ++b) {
    out.zz[b] = q.template block<B, B>(b * B, b * B).template cast<S>();
    out.za[b] = q.template block<B, 1>(b * B, NX).template cast<S>();
  }
  out.aa = static_cast<S>(q(NX, NX));
  return out;
}

namespace detail {

// Augmented generator for [z_b; a; a'] with a' constant over the step.
template <int B>
Eigen::Matrix<double, B + 2, B + 2> augmented(const Eigen::Matrix<double, B, B>& ab,
                                              const Eigen::Matrix<double, B, 1>& bgb) {
  Eigen::Matrix<double, B + 2, B + 2> m = Eigen::Matrix<double, B + 2, B + 2>::Zero();
  m.template topLeftCorner<B, B>() = ab;
  m.template block<B, 1>(0, B) = bgb;
  m(B, B + 1) = 1.0;
  return m;
}

}  // namespace detail

// Exact FOH discretisation of spec over a step h.
template <typename S, int NX, int B>
Lti<S, NX, B> discretise(const LtiSpec<NX>& spec, double h) {
  Lti<S, NX, B> out;
  for (int b = 0; b < NX / B; ++b) {
    const Eigen::Matrix<double, B, B> ab = spec.a.template block<B, B>(b * B, b * B);
    const Eigen::Matrix<double, B, 1> bgb = spec.bg.template segment<B>(b * B);
    // exp(Abar h) = [[Phi, P, Q], [0, 1, h], [0, 0, 1]] and
    // z(h) = Phi z0 + P a0 + Q (a1 - a0) / h.
    const Eigen::Matrix<double, B + 2, B + 2> e = numeric::expm(
        Eigen::Matrix<double, B + 2, B + 2>(detail::augmented<B>(ab, bgb) * h));
    const Eigen::Matrix<double, B, 1> p = e.template block<B, 1>(0, B);
    const Eigen::Matrix<double, B, 1> q = e.template block<B, 1>(0, B + 1);
    out.phi[b] = e.template topLeftCorner<B, B>().template cast<S>();
    out.gam[b].col(0) = (p - q / h).template cast<S>();
    out.gam[b].col(1) = (q / h).template cast<S>();
    out.a[b] = ab.template cast<S>();
    out.bg[b] = bgb.template cast<S>();
    out.bf[b] = spec.bf.template segment<B>(b * B).template cast<S>();
  }
  return out;
}

// Exact integral over a step h of [z; a]^T Q [z; a]; Q (NX+1 square, symmetric)
// must not couple different blocks of z (it may couple any block with a).
template <typename S, int NX, int B>
QuadIntegral<S, NX, B> quad_integral(const LtiSpec<NX>& spec,
                                     const Eigen::Matrix<double, NX + 1, NX + 1>& q, double h) {
  constexpr int D = B + 2;
  QuadIntegral<S, NX, B> out;
  for (int b = 0; b < NX / B; ++b) {
    const Eigen::Matrix<double, B, B> ab = spec.a.template block<B, B>(b * B, b * B);
    const Eigen::Matrix<double, B, 1> bgb = spec.bg.template segment<B>(b * B);
    // Weight on [z_b; a; a']: this block's part of Q; the a-a term goes to block 0.
    Eigen::Matrix<double, D, D> qb = Eigen::Matrix<double, D, D>::Zero();
    qb.template topLeftCorner<B, B>() = q.template block<B, B>(b * B, b * B);
    qb.template block<B, 1>(0, B) = q.template block<B, 1>(b * B, NX);
    qb.template block<1, B>(B, 0) = q.template block<1, B>(NX, b * B);
    if (b == 0) qb(B, B) = q(NX, NX);
    // Van Loan: exp([[-Abar^T, Qb], [0, Abar]] h) = [[., G], [0, F]],
    // integral_0^h exp(Abar^T s) Qb exp(Abar s) ds = F^T G.
    const Eigen::Matrix<double, D, D> abar = detail::augmented<B>(ab, bgb);
    Eigen::Matrix<double, 2 * D, 2 * D> vl = Eigen::Matrix<double, 2 * D, 2 * D>::Zero();
    vl.template topLeftCorner<D, D>() = -abar.transpose();
    vl.template topRightCorner<D, D>() = qb;
    vl.template bottomRightCorner<D, D>() = abar;
    const Eigen::Matrix<double, 2 * D, 2 * D> e =
        numeric::expm(Eigen::Matrix<double, 2 * D, 2 * D>(vl * h));
    const Eigen::Matrix<double, D, D> w =
        e.template bottomRightCorner<D, D>().transpose() * e.template topRightCorner<D, D>();
    // Change of variables [z; a0; a'] = T [z; a0; a1], a' = (a1 - a0) / h.
    Eigen::Matrix<double, D, D> t = Eigen::Matrix<double, D, D>::Identity();
    t(B + 1, B) = -1.0 / h;
    t(B + 1, B + 1) = 1.0 / h;
    const Eigen::Matrix<double, D, D> wt = t.transpose() * w * t;
    out.w[b] = (0.5 * (wt + wt.transpose())).template cast<S>();
  }
  return out;
}

}  // namespace vines
