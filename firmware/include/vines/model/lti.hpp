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
// computed once in double (lti_build.hpp), then stored in the loop's scalar S.
#pragma once

#include <cmath>

#include <Eigen/Core>

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

}  // namespace vines
