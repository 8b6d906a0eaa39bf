// Building the linear part's step (lti.hpp) once, in double: the exact
// first-order-hold discretisation of each form, the exact step integrals of
// quadratic forms (Van Loan 1978), the instantaneous forms, and the Lyapunov
// split of E_e. build_model (build_model.hpp) calls these; the loop never does.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/LU>

#include "vines/model/lti.hpp"
#include "vines/numeric/expm.hpp"

namespace vines {

// ---------------------------------------------------------------- builders

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

// Exact FOH step of z' = ab z + bgb a_g over h: Phi and the gains of (a0, a1).
template <int B>
struct Foh {
  Eigen::Matrix<double, B, B> phi;
  Eigen::Matrix<double, B, 1> g0, g1;
};
template <int B>
Foh<B> foh(const Eigen::Matrix<double, B, B>& ab, const Eigen::Matrix<double, B, 1>& bgb, double h) {
  // exp(Abar h) = [[Phi, P, Q], [0, 1, h], [0, 0, 1]] and
  // z(h) = Phi z0 + P a0 + Q (a1 - a0) / h.
  const Eigen::Matrix<double, B + 2, B + 2> e =
      numeric::expm(Eigen::Matrix<double, B + 2, B + 2>(augmented<B>(ab, bgb) * h));
  const Eigen::Matrix<double, B, 1> p = e.template block<B, 1>(0, B);
  const Eigen::Matrix<double, B, 1> q = e.template block<B, 1>(0, B + 1);
  return {e.template topLeftCorner<B, B>(), p - q / h, q / h};
}

// Exact integral over h of xi^T qb xi, xi = [z; a; a'] (Van Loan:
// exp([[-Abar^T, Qb], [0, Abar]] h) = [[., G], [0, F]], integral = F^T G), as a
// symmetric form in [z; a0; a1].
template <int B>
Eigen::Matrix<double, B + 2, B + 2> van_loan(const Eigen::Matrix<double, B, B>& ab,
                                             const Eigen::Matrix<double, B, 1>& bgb,
                                             const Eigen::Matrix<double, B + 2, B + 2>& qb, double h) {
  constexpr int D = B + 2;
  const Eigen::Matrix<double, D, D> abar = augmented<B>(ab, bgb);
  Eigen::Matrix<double, 2 * D, 2 * D> vl = Eigen::Matrix<double, 2 * D, 2 * D>::Zero();
  vl.template topLeftCorner<D, D>() = -abar.transpose();
  vl.template topRightCorner<D, D>() = qb;
  vl.template bottomRightCorner<D, D>() = abar;
  const Eigen::Matrix<double, 2 * D, 2 * D> e = numeric::expm(Eigen::Matrix<double, 2 * D, 2 * D>(vl * h));
  const Eigen::Matrix<double, D, D> w =
      e.template bottomRightCorner<D, D>().transpose() * e.template topRightCorner<D, D>();
  // Change of variables [z; a0; a'] = T [z; a0; a1], a' = (a1 - a0) / h.
  Eigen::Matrix<double, D, D> t = Eigen::Matrix<double, D, D>::Identity();
  t(B + 1, B) = -1.0 / h;
  t(B + 1, B + 1) = 1.0 / h;
  const Eigen::Matrix<double, D, D> wt = t.transpose() * w * t;
  return 0.5 * (wt + wt.transpose());
}

// Mode j's 2x2 part of an NX-square matrix in the [q; q'] layout.
template <int P, typename Mat>
Eigen::Matrix2d mode_block(const Mat& m, int j) {
  Eigen::Matrix2d b;
  b << m(j, j), m(j, P + j), m(P + j, j), m(P + j, P + j);
  return b;
}

}  // namespace detail

template <typename S, int P>
ModalLti<S, P> discretise_modal(const LtiSpec<2 * P>& spec, double h) {
  ModalLti<S, P> out;
  for (int j = 0; j < P; ++j) {
    const Eigen::Matrix2d ab = detail::mode_block<P>(spec.a, j);
    const Eigen::Vector2d bgb(spec.bg(j), spec.bg(P + j));
    const detail::Foh<2> f = detail::foh<2>(ab, bgb, h);
    out.p11(j) = static_cast<S>(f.phi(0, 0));
    out.p12(j) = static_cast<S>(f.phi(0, 1));
    out.p21(j) = static_cast<S>(f.phi(1, 0));
    out.p22(j) = static_cast<S>(f.phi(1, 1));
    out.gx0(j) = static_cast<S>(f.g0(0));
    out.gx1(j) = static_cast<S>(f.g1(0));
    out.gv0(j) = static_cast<S>(f.g0(1));
    out.gv1(j) = static_cast<S>(f.g1(1));
    out.ak(j) = static_cast<S>(ab(1, 0));
    out.ac(j) = static_cast<S>(ab(1, 1));
    out.bgv(j) = static_cast<S>(bgb(1));
    out.bfv(j) = static_cast<S>(spec.bf(P + j));
  }
  return out;
}

template <typename S, int NX>
DenseLti<S, NX> discretise_dense(const LtiSpec<NX>& spec, double h) {
  const detail::Foh<NX> f = detail::foh<NX>(spec.a, spec.bg, h);
  DenseLti<S, NX> out;
  out.phi = f.phi.template cast<S>();
  out.g0 = f.g0.template cast<S>();
  out.g1 = f.g1.template cast<S>();
  return out;
}

// Exact integral over a step h of [z; a]^T Q [z; a] (Q: NX+1 square, symmetric).
template <typename S, int P>
ModalQuad<S, P> quad_integral_modal(const LtiSpec<2 * P>& spec,
                                    const Eigen::Matrix<double, 2 * P + 1, 2 * P + 1>& q, double h) {
  constexpr int NX = 2 * P;
  ModalQuad<S, P> out;
  Eigen::Matrix2d aa = Eigen::Matrix2d::Zero();  // the a-a part, summed over modes
  for (int j = 0; j < P; ++j) {
    // Weight on [q_j; q_j'; a; a']: this mode's part of Q; the a-a term once.
    Eigen::Matrix4d qb = Eigen::Matrix4d::Zero();
    qb.topLeftCorner<2, 2>() = detail::mode_block<P>(q, j);
    qb(0, 2) = qb(2, 0) = q(j, NX);
    qb(1, 2) = qb(2, 1) = q(P + j, NX);
    if (j == 0) qb(2, 2) = q(NX, NX);
    const Eigen::Matrix4d w = detail::van_loan<2>(detail::mode_block<P>(spec.a, j),
                                                  Eigen::Vector2d(spec.bg(j), spec.bg(P + j)), qb, h);
    out.qq(j) = static_cast<S>(w(0, 0));
    out.qv(j) = static_cast<S>(2 * w(0, 1));
    out.vv(j) = static_cast<S>(w(1, 1));
    out.q0(j) = static_cast<S>(2 * w(0, 2));
    out.q1(j) = static_cast<S>(2 * w(0, 3));
    out.v0(j) = static_cast<S>(2 * w(1, 2));
    out.v1(j) = static_cast<S>(2 * w(1, 3));
    aa += w.bottomRightCorner<2, 2>();
  }
  out.c00 = static_cast<S>(aa(0, 0));
  out.c01 = static_cast<S>(2 * aa(0, 1));
  out.c11 = static_cast<S>(aa(1, 1));
  return out;
}

template <typename S, int NX>
DenseQuad<S, NX> quad_integral_dense(const LtiSpec<NX>& spec, const Eigen::Matrix<double, NX + 1, NX + 1>& q,
                                     double h) {
  Eigen::Matrix<double, NX + 2, NX + 2> qb = Eigen::Matrix<double, NX + 2, NX + 2>::Zero();
  qb.template topLeftCorner<NX + 1, NX + 1>() = q;
  DenseQuad<S, NX> out;
  out.w = detail::van_loan<NX>(spec.a, spec.bg, qb, h).template cast<S>();
  return out;
}

template <typename S, int P>
ModalForm<S, P> form_modal(const Eigen::Matrix<double, 2 * P + 1, 2 * P + 1>& q) {
  constexpr int NX = 2 * P;
  ModalForm<S, P> out;
  for (int j = 0; j < P; ++j) {
    out.qq(j) = static_cast<S>(q(j, j));
    out.qv(j) = static_cast<S>(2 * q(j, P + j));
    out.vv(j) = static_cast<S>(q(P + j, P + j));
    out.qa(j) = static_cast<S>(2 * q(j, NX));
    out.va(j) = static_cast<S>(2 * q(P + j, NX));
  }
  out.aa = static_cast<S>(q(NX, NX));
  out.positions_only = out.qv.isZero() && out.vv.isZero() && out.qa.isZero() && out.va.isZero() && out.aa == S(0);
  return out;
}

// E_e by a Lyapunov identity. With X_j solving A_j^T X_j + X_j A_j = -Q_j
// for each mode and V(z) = z^T X z,
//   integral over a step of z^T Q z = V(z0) - V(z1) + integral of 2 a_g b^T X z,
// so over a run of exact steps the boundary terms telescope (the loop adds V
// where a run starts and takes it off where it ends) and a step costs only
// the last integral, a linear form of z0 in (a0, a1): rows->lq0.. l11.
// Needs every mode damped (zeta >= 1e-4: X grows like 1 / zeta) and Q a
// form in z alone; returns false, leaving rows and v alone, otherwise.
template <typename S, int P>
bool lyapunov_split(const LtiSpec<2 * P>& spec, const Eigen::Matrix<double, 2 * P + 1, 2 * P + 1>& q, double h,
                    ModalRows<S, P>* rows, ModalForm<S, P>* v) {
  constexpr int NX = 2 * P;
  if (!q.col(NX).isZero()) return false;
  Eigen::Matrix<double, NX + 1, NX + 1> x = Eigen::Matrix<double, NX + 1, NX + 1>::Zero(), qlin = x;
  for (int j = 0; j < P; ++j) {
    const Eigen::Matrix2d a = detail::mode_block<P>(spec.a, j), qj = detail::mode_block<P>(q, j);
    if (a.isZero() && qj.isZero()) continue;  // a padding mode (see Layout)
    const double det = a.determinant(), tr = a.trace();
    if (!(det > 0.0) || !(-tr >= 2e-4 * std::sqrt(det))) return false;
    // The three equations of the symmetric 2x2 Lyapunov equation.
    Eigen::Matrix3d mat;
    mat << 2 * a(0, 0), 2 * a(1, 0), 0.0, a(0, 1), a(0, 0) + a(1, 1), a(1, 0), 0.0, 2 * a(0, 1), 2 * a(1, 1);
    const Eigen::Vector3d xs = mat.partialPivLu().solve(Eigen::Vector3d(-qj(0, 0), -qj(0, 1), -qj(1, 1)));
    x(j, j) = xs(0);
    x(j, P + j) = x(P + j, j) = xs(1);
    x(P + j, P + j) = xs(2);
    Eigen::Matrix2d xj;
    xj << xs(0), xs(1), xs(1), xs(2);
    const Eigen::Vector2d c = xj * Eigen::Vector2d(spec.bg(j), spec.bg(P + j));
    qlin(j, NX) = qlin(NX, j) = c(0);
    qlin(P + j, NX) = qlin(NX, P + j) = c(1);
  }
  const ModalQuad<S, P> lin = quad_integral_modal<S, P>(spec, qlin, h);
  rows->lq0 = lin.q0;
  rows->lq1 = lin.q1;
  rows->lv0 = lin.v0;
  rows->lv1 = lin.v1;
  rows->l00 = lin.c00;
  rows->l01 = lin.c01;
  rows->l11 = lin.c11;
  *v = form_modal<S, P>(x);
  return true;
}

template <typename S, int NX>
DenseForm<S, NX> form_dense(const Eigen::Matrix<double, NX + 1, NX + 1>& q) {
  DenseForm<S, NX> out;
  out.q = q.template cast<S>();
  return out;
}

}  // namespace vines
