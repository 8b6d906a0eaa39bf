// The linear part of the model (frame, plus a TMD when there is one) as
//   z' = A z + bg a_g(t) + bf F(t),   z = [positions; velocities] (P each),
// in one of two forms:
//   - modal (no device, VI NES): P independent oscillators, every matrix is
//     diagonal per block, stored as structure-of-arrays vectors over the
//     modes so that a step is a handful of vector operations;
//   - dense (TMD): one full block.
// Over a sensor step the ground acceleration is linear between two samples and
// F = 0, so the step is exact (first-order-hold discretisation):
//   z_{k+1} = Phi z_k + Gam [a_k, a_{k+1}]^T.
// Quadratic integrals of the state over a step (strain energy, damping
// dissipation, input work) are exact too (Van Loan 1978). Everything is
// computed once in double, then stored in the loop's scalar S.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/LU>

#include "vines/numeric/expm.hpp"
#include "vines/numeric/inline.hpp"
#include "vines/numeric/sums.hpp"

namespace vines {

// Continuous-time description, in double, handed to the builders below. In
// the modal form A, bg, bf and every quadratic form must not couple modes:
// only entries (j, j), (j, P+j), (P+j, j), (P+j, P+j) are read.
template <int NX>
struct LtiSpec {
  Eigen::Matrix<double, NX, NX> a;
  Eigen::Matrix<double, NX, 1> bg;  // ground acceleration input
  Eigen::Matrix<double, NX, 1> bf;  // device force input (on the device floor)
};

// ---------------------------------------------------------------- modal form

template <typename S, int P>
struct ModalLti {
  using VecX = Eigen::Matrix<S, 2 * P, 1>;
  using VecP = Eigen::Matrix<S, P, 1>;
  // Exact step: q1 = p11 q + p12 q' + gx0 a0 + gx1 a1, q1' likewise.
  VecP p11, p12, p21, p22, gx0, gx1, gv0, gv1;
  // Continuous time: q'' = ak q + ac q' + bgv a_g + bfv F.
  VecP ak, ac, bgv, bfv;

  void step(VecX& z, S a0, S a1) const {
    const auto q = z.template head<P>().array();
    const auto v = z.template tail<P>().array();
    const VecP q1 = p11.array() * q + p12.array() * v + gx0.array() * a0 + gx1.array() * a1;
    z.template tail<P>() = p21.array() * q + p22.array() * v + gv0.array() * a0 + gv1.array() * a1;
    z.template head<P>() = q1;
  }

  // z' for sub-stepping: ground acceleration ag, device force f.
  VecX derivative(const VecX& z, S ag, S f) const {
    VecX d;
    d.template head<P>() = z.template tail<P>();
    d.template tail<P>() = ak.array() * z.template head<P>().array() +
                           ac.array() * z.template tail<P>().array() + bgv.array() * ag + bfv.array() * f;
    return d;
  }

  // Velocity jump of an impulse j of the device force.
  void impulse(VecX& z, S j) const { z.template tail<P>() += bfv * j; }
};

// What the loop reads off every exact step, taken in the same pass over the
// modes as the step itself: the top floor and the device floor after it, a
// cheap bound on every floor (sum of |q_j| max_i |phi_ij|, non-finite if any
// position is), a probe non-finite if any velocity is, and a linear form of
// the state before the step in (a0, a1) (the E_e step integral, see
// build_model). The modal probe is vt itself: a sum over every mode with
// finite weights, so an infinity or NaN in any mode reaches it (0 * inf is
// NaN).
template <typename S>
struct StepRead {
  S xt, vt, bound, lin, xf, vf, vprobe;
};

template <typename S, int P>
struct ModalRows {
  using VecP = Eigen::Matrix<S, P, 1>;
  VecP top = VecP::Zero(), dev = VecP::Zero(), bound = VecP::Zero();  // top floor, device floor, floor bound
  // lin = sum q (lq0 a0 + lq1 a1) + v (lv0 a0 + lv1 a1)
  VecP lq0 = VecP::Zero(), lq1 = VecP::Zero(), lv0 = VecP::Zero(), lv1 = VecP::Zero();
  S l00 = S(0), l01 = S(0), l11 = S(0);  //     + a0 (l00 a0 + l01 a1) + l11 a1^2
  bool dev_is_top = true;       // the device floor is the top floor (xf = xt)
};

// Exact step of z0 to z1 with its readouts (WithDev: a device floor is
// read). L: the SIMD width the modes are padded to (numeric/sums.hpp).
template <bool WithDev, int L, typename S, int P>
VINES_INLINE StepRead<S> step_read(const ModalLti<S, P>& l, const ModalRows<S, P>& rw,
                                   const Eigen::Matrix<S, 2 * P, 1>& z0, Eigen::Matrix<S, 2 * P, 1>& z1, S a0, S a1) {
  using Arr = Eigen::Array<S, P, 1>;
  using Pack = numeric::Lanes<S, L>;
  const auto q = z0.template head<P>().array();
  const auto v = z0.template tail<P>().array();
  // The E_e form's parts in a0 and a1, from the state before the step.
  Pack y0 = numeric::fold_dot<L, P, S>(rw.lq0.array(), q), y1 = numeric::fold_dot<L, P, S>(rw.lq1.array(), q);
  numeric::fold_dot_add<L, P>(y0, rw.lv0.array(), v);
  numeric::fold_dot_add<L, P>(y1, rw.lv1.array(), v);
  const Arr q1 = l.p11.array() * q + l.p12.array() * v + l.gx0.array() * a0 + l.gx1.array() * a1;
  const Arr v1 = l.p21.array() * q + l.p22.array() * v + l.gv0.array() * a0 + l.gv1.array() * a1;
  // The top floor's x and v and the floor bound, after it.
  const Pack xt = numeric::fold_dot<L, P, S>(rw.top.array(), q1);
  const Pack vt = numeric::fold_dot<L, P, S>(rw.top.array(), v1);
  const Pack bound = numeric::fold_dot<L, P, S>(rw.bound.array(), q1.abs());
  const numeric::Lanes<S, 4> sums = numeric::lane_sums<S, L>(xt, vt, bound, y0 * a0 + y1 * a1);
  StepRead<S> r;
  r.xt = sums(0);
  r.vt = sums(1);
  r.bound = sums(2);
  r.lin = sums(3) + a0 * (rw.l00 * a0 + rw.l01 * a1) + rw.l11 * a1 * a1;
  r.xf = r.xt;
  r.vf = r.vt;
  if (WithDev && !rw.dev_is_top) {
    r.xf = (rw.dev.array() * q1).sum();
    r.vf = (rw.dev.array() * v1).sum();
  }
  r.vprobe = r.vt;
  z1.template head<P>() = q1.matrix();
  z1.template tail<P>() = v1.matrix();
  return r;
}

// Integral over one step of a quadratic form in [z; a_g], as a form in
// (q, q', a0, a1): cross terms already doubled.
template <typename S, int P>
struct ModalQuad {
  using VecX = Eigen::Matrix<S, 2 * P, 1>;
  using VecP = Eigen::Matrix<S, P, 1>;
  VecP qq, qv, vv, q0, q1, v0, v1;
  S c00 = S(0), c01 = S(0), c11 = S(0);

  S eval(const VecX& z, S a0, S a1) const {
    const auto q = z.template head<P>().array();
    const auto v = z.template tail<P>().array();
    return (q * (qq.array() * q + qv.array() * v + q0.array() * a0 + q1.array() * a1)).sum() +
           (v * (vv.array() * v + v0.array() * a0 + v1.array() * a1)).sum() +
           a0 * (c00 * a0 + c01 * a1) + c11 * a1 * a1;
  }
};

// Instantaneous quadratic form [z; a]^T Q [z; a] (cross terms doubled).
template <typename S, int P>
struct ModalForm {
  using VecX = Eigen::Matrix<S, 2 * P, 1>;
  using VecP = Eigen::Matrix<S, P, 1>;
  VecP qq, qv, vv, qa, va;
  S aa = S(0);
  bool positions_only = false;  // only qq is nonzero (the strain energy)

  // The form when it has positions only (q: the P position coordinates).
  template <typename Q>
  S eval_positions(const Eigen::MatrixBase<Q>& q) const {
    return (q.array() * qq.array() * q.array()).sum();
  }

  template <typename Z>  // z: a 2P vector or a segment of one
  S eval(const Eigen::MatrixBase<Z>& z, S ag) const {
    if (positions_only) return eval_positions(z.template head<P>());
    const auto q = z.template head<P>().array();
    const auto v = z.template tail<P>().array();
    return (q * (qq.array() * q + qv.array() * v + qa.array() * ag)).sum() +
           (v * (vv.array() * v + va.array() * ag)).sum() + aa * ag * ag;
  }
};

// ---------------------------------------------------------------- dense form

template <typename S, int NX>
// Only the exact step: the dense form carries the TMD, which has no contact
// force (the sub-stepper's derivative and impulses are the modal form's), so
// a board's RAM holds no continuous-time matrix.
struct DenseLti {
  using VecX = Eigen::Matrix<S, NX, 1>;
  Eigen::Matrix<S, NX, NX> phi;
  VecX g0, g1;

  void step(VecX& z, S a0, S a1) const {
    const VecX z0 = z;  // lazyProduct reads z while it is written: no aliasing
    z = phi.lazyProduct(z0) + g0 * a0 + g1 * a1;
  }
};

template <typename S, int NX>
struct DenseQuad {
  using VecX = Eigen::Matrix<S, NX, 1>;
  Eigen::Matrix<S, NX + 2, NX + 2> w;

  S eval(const VecX& z, S a0, S a1) const {
    Eigen::Matrix<S, NX + 2, 1> xi;
    xi << z, a0, a1;
    return xi.dot(w.lazyProduct(xi));
  }
};

template <typename S, int NX>
struct DenseForm {
  using VecX = Eigen::Matrix<S, NX, 1>;
  Eigen::Matrix<S, NX + 1, NX + 1> q;

  S eval(const VecX& z, S ag) const {
    Eigen::Matrix<S, NX + 1, 1> xi;
    xi << z, ag;
    return xi.dot(q.lazyProduct(xi));
  }
};

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
