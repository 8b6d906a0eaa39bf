// The frame with a tuned mass damper in fixed point (issue 34,
// docs/fixed_point.md, "The TMD"). The double TMD model is dense
// (lti.hpp, DenseLti: z = [x_1..x_N, x_d; v_1..v_N, v_d], non-classical
// damping, z1 = Phi z0 + g0 a0 + g1 a1); here its exact step is put in real
// block-diagonal form, once, in double, when the model is built:
//   each complex pair of Phi's eigenvalues, lambda = alpha + i beta with
//   eigenvector a + i b, gives Phi [a b] = [a b] [[alpha, beta], [-beta, alpha]];
//   with T = [a_1 .. a_P, b_1 .. b_P] and y = T^-1 z the step is P
//   independent 2x2 blocks, ModalLti's structure (head y_b = a_b's
//   coordinate, tail y_{P+b} = b_b's), so ModalLti<Fixed<F>, P>::step runs
//   it unchanged, as it runs the bare frame's modes (fixed/frame.hpp).
// (Real eigenvalues, overdamped motions, pair up as diagonal blocks, each
// coordinate in a unit of its own; Phi has none unless a motion's damping
// passes critical, as a TMD's dashpot far too stiff for its spring does.)
//
// Units (sa, amp the scales given; y_b the block's two coordinates):
//   block b      y / u_b, both coordinates: u_b = amp |y_b,static|, the
//                block's static response to a ground acceleration sa (so
//                the rotation's entries stay alpha, +-beta, below 1)
//   a_g          sa
//   top floor    Lt = sum_k |Tu_top,k|, its speed Vt = sum_k |Tu_vtop,k|
//                (Tu = T diag(u): the state when every coordinate is at 1)
//   story i      D_i = sum_k |Tu_i,k - Tu_i-1,k|, its drift
//   the TMD      Ld = sum_k |Tu_d,k|, Vd = sum_k |Tu_vd,k| (its initial
//                conditions, and read back)
//   E_e          sum_i (1/2) k_i D_i^2 h: the frame's strain energy (the
//                stories' springs, not the TMD's, as the double model's
//                E_e) at each step's end times h
// Each readout is a dot product over the 2P coordinates summed 64 bits wide
// and saturated once (gain_dot): the blocks' parts of a floor's motion
// cancel one another.
//
// The eigenvectors' phase: each complex eigenvector is turned so that its
// displacement half psi = a_x + i b_x has psi^T psi real and positive
// (a_x orthogonal to b_x, |a_x| >= |b_x|), and its largest displacement
// entry positive (its length does not matter: the units absorb it). For a
// classically damped mode psi is then real: the head is proportional to the
// mode's displacement q and the tail to (q' + zeta w q) / w_d, the bare
// frame's (q, q' / w) in one unit (fixed/frame.hpp) up to the damping's
// small term; with the TMD's non-classical damping the head is still the
// displacement-like coordinate. The phase only turns a block's plane (the
// rotation and the block's range |y_b| do not depend on it), so it is
// chosen for readable coordinates. Making the whole [x; v]
// eigenvector's a and b orthogonal instead would depend on the units of v
// against x, and with v in units of w x (|a| ~ |b|) the phase that does it
// is ill-determined: 45 degrees off for a classically damped mode.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>
#if VINES_MODEL_REPORT
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#endif

#include "vines/fixed/frame.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/fixed_gain.hpp"
#include "vines/numeric/fixed_math.hpp"

namespace vines::fixed {

// The fixed-point model: N = P - 1 stories and the TMD, 2P coordinates in
// P blocks. Its data is a FixedFrameData<FixedTmd> (fixed/frame.hpp): the
// blocks in z, the last sample, the top floor's peaks, E_e.
template <int F, int P>
struct FixedTmd {
  using Q = numeric::Fixed<F>;
  using G = numeric::Gain;
  using VecX = Eigen::Matrix<Q, 2 * P, 1>;
  using GainX = std::array<G, 2 * P>;
  static constexpr int kP = P, kStories = P - 1;

  // In double, for reading results back and for reports (the host's: a
  // board would keep only the step's part below).
  double h = 0, sa = 0, top_length = 0, top_speed = 0, ee_unit = 0;
  double dev_length = 0, dev_speed = 0;   // Ld, Vd [m, m/s]
  Eigen::Matrix<double, 2 * P, 1> unit;   // u_b of each coordinate (the block's)
  Eigen::Matrix<double, 2 * P, 2 * P> back;  // z [SI] = back y: T diag(u)
  double condition = 0;                   // of T (its columns at unit length): 1 is orthogonal
  int real_blocks = 0;                    // blocks of two real eigenvalues
  bool ok = false;                        // the block form was found (T invertible)

  ModalLti<Q, P> lti;        // the exact step, block by block, in u
  GainX top_x, top_v;        // x_top / Lt, v_top / Vt from the blocks
  std::array<GainX, P - 1> drift;  // story i's drift / D_i from the blocks
  std::array<G, P - 1> ee;         // (1/2) k_i D_i^2 h in E_e's unit
  GainX init_x, init_v;      // the blocks of a TMD displaced by Ld / moving at Vd
};

#if VINES_MODEL_REPORT
// The fixed-point TMD model of the double model m (a TMD: dense form), for
// ground accelerations up to sa [m/s^2] amplified up to amp. Host side:
// double, an eigendecomposition and an inverse; fixed-size, no heap.
template <int F, int N>
FixedTmd<F, N + 1> build_fixed_tmd(const Model<double, N, TmdDevice>& m, double sa, double amp) {
  constexpr int P = N + 1, NX = 2 * P;
  using Out = FixedTmd<F, P>;
  using Q = typename Out::Q;
  using G = numeric::Gain;
  using MatX = Eigen::Matrix<double, NX, NX>;
  using VecX = Eigen::Matrix<double, NX, 1>;
  using CVec = Eigen::Matrix<std::complex<double>, NX, 1>;
  Out o;
  o.h = m.h;
  o.sa = sa;

  // The real block form of Phi: T's columns and each block's 2x2 step.
  const MatX& phi = m.lti.phi;
  Eigen::EigenSolver<MatX> es(phi, true);
  if (es.info() != Eigen::Success) return o;
  const auto lambda = es.eigenvalues();
  const auto vectors = es.eigenvectors();
  MatX t = MatX::Zero();
  Eigen::Matrix<double, P, 1> p11, p12, p21, p22;
  int blocks = 0;
  int real_left = -1;  // a real eigenvalue waiting for its pair
  // The largest displacement entry of a real vector made positive.
  auto sign_of = [](const VecX& x) {
    int at = 0;
    x.template head<P>().cwiseAbs().maxCoeff(&at);
    return x(at) < 0.0 ? -1.0 : 1.0;
  };
  const double tiny = 1e-12;
  for (int k = 0; k < NX; ++k) {
    const std::complex<double> l = lambda(k);
    if (l.imag() < -tiny * std::abs(l)) continue;  // the conjugate of a pair taken
    if (blocks >= P) return o;
    if (l.imag() > tiny * std::abs(l)) {
      CVec v = vectors.col(k);
      // psi^T psi real and positive: a_x orthogonal to b_x, |a_x| >= |b_x|.
      const std::complex<double> s = (v.template head<P>().array() * v.template head<P>().array()).sum();
      v *= std::polar(1.0, -0.5 * std::arg(s));
      VecX a = v.real(), b = v.imag();
      const double sg = sign_of(a), norm = a.template head<P>().norm();
      a *= sg / norm;
      b *= sg / norm;
      t.col(blocks) = a;
      t.col(P + blocks) = b;
      p11(blocks) = p22(blocks) = l.real();
      p12(blocks) = l.imag();
      p21(blocks) = -l.imag();
      ++blocks;
    } else if (real_left < 0) {
      real_left = k;
    } else {
      VecX a = vectors.col(real_left).real(), b = vectors.col(k).real();
      a *= sign_of(a) / a.norm();
      b *= sign_of(b) / b.norm();
      t.col(blocks) = a;
      t.col(P + blocks) = b;
      p11(blocks) = lambda(real_left).real();
      p22(blocks) = l.real();
      p12(blocks) = p21(blocks) = 0.0;
      real_left = -1;
      ++blocks;
      ++o.real_blocks;
    }
  }
  if (blocks != P || real_left >= 0) return o;
  {
    const Eigen::JacobiSVD<MatX> svd(t.colwise().normalized());
    const auto sv = svd.singularValues();
    o.condition = sv(NX - 1) > 0.0 ? sv(0) / sv(NX - 1) : HUGE_VAL;
    if (!(o.condition < 1e8)) return o;
  }
  const Eigen::PartialPivLU<MatX> lu(t);
  const VecX h0 = lu.solve(m.lti.g0), h1 = lu.solve(m.lti.g1);

  // Each block's unit: amp times its static response to sa (a constant
  // ground acceleration: y = (I - Lambda)^-1 (h0 + h1) sa).
  for (int b = 0; b < P; ++b) {
    Eigen::Matrix2d lam;
    lam << p11(b), p12(b), p21(b), p22(b);
    const Eigen::Vector2d g(h0(b) + h1(b), h0(P + b) + h1(P + b));
    const Eigen::Vector2d y = (Eigen::Matrix2d::Identity() - lam).partialPivLu().solve(g) * sa;
    if (p12(b) == 0.0) {  // two real motions: a unit each
      o.unit(b) = amp * std::fabs(y(0));
      o.unit(P + b) = amp * std::fabs(y(1));
    } else {
      o.unit(b) = o.unit(P + b) = amp * y.norm();
    }
    for (int c : {b, P + b})
      if (!(o.unit(c) > 0.0)) o.unit(c) = 1.0;  // not driven by the ground (then at rest unless started)
  }
  o.back = t * o.unit.asDiagonal();
  const MatX inv = lu.inverse();  // y = inv z

  // The step in the units: p's as they are (a rotation in both coordinates'
  // common unit), the gains of the samples divided by the units.
  auto put = [](Eigen::Matrix<Q, P, 1>& dst, const Eigen::Matrix<double, P, 1>& src) {
    dst = src.template cast<Q>();
  };
  put(o.lti.p11, p11);
  put(o.lti.p12, p12);
  put(o.lti.p21, p21);
  put(o.lti.p22, p22);
  const VecX g0u = (h0 * sa).cwiseQuotient(o.unit), g1u = (h1 * sa).cwiseQuotient(o.unit);
  put(o.lti.gx0, g0u.template head<P>());
  put(o.lti.gx1, g1u.template head<P>());
  put(o.lti.gv0, g0u.template tail<P>());
  put(o.lti.gv1, g1u.template tail<P>());
  for (auto* v : {&o.lti.ak, &o.lti.ac, &o.lti.bgv, &o.lti.bfv}) v->setConstant(Q(0));

  // The readouts: rows of back, each divided by its unit (the sum of its
  // entries' magnitudes: a readout is in range while every coordinate is).
  const int top = N - 1, dev = N;
  auto gains = [](const VecX& row, double unit) {
    typename Out::GainX g;
    for (int k = 0; k < NX; ++k) g[static_cast<std::size_t>(k)] = G(row(k) / unit);
    return g;
  };
  const VecX xtop = o.back.row(top).transpose(), vtop = o.back.row(P + top).transpose();
  o.top_length = xtop.cwiseAbs().sum();
  o.top_speed = vtop.cwiseAbs().sum();
  o.top_x = gains(xtop, o.top_length);
  o.top_v = gains(vtop, o.top_speed);
  Eigen::Matrix<double, N, 1> dunit;
  o.ee_unit = 0;
  for (int i = 0; i < N; ++i) {
    VecX d = o.back.row(i).transpose();
    if (i > 0) d -= o.back.row(i - 1).transpose();
    dunit(i) = d.cwiseAbs().sum();
    o.drift[static_cast<std::size_t>(i)] = gains(d, dunit(i));
    o.ee_unit += 0.5 * m.frame.k(i) * dunit(i) * dunit(i) * m.h;
  }
  for (int i = 0; i < N; ++i)
    o.ee[static_cast<std::size_t>(i)] = G(0.5 * m.frame.k(i) * dunit(i) * dunit(i) * m.h / o.ee_unit);
  // The TMD's initial conditions: the blocks of a unit displacement and speed.
  o.dev_length = o.back.row(dev).cwiseAbs().sum();
  o.dev_speed = o.back.row(P + dev).cwiseAbs().sum();
  for (int k = 0; k < NX; ++k) {
    o.init_x[static_cast<std::size_t>(k)] = G(inv(k, dev) * o.dev_length / o.unit(k));
    o.init_v[static_cast<std::size_t>(k)] = G(inv(k, P + dev) * o.dev_speed / o.unit(k));
  }
  o.ok = true;
  return o;
}
#endif  // VINES_MODEL_REPORT

// At the TMD's initial displacement x0 [Ld] and speed v0 [Vd] relative to
// the ground (its floor at rest), the first sample a0 [sa]: each coordinate
// summed 64 bits wide, saturated once.
template <int F, int P>
void fixed_tmd_init(const FixedTmd<F, P>& m, FixedFrameData<FixedTmd<F, P>>& d, numeric::Fixed<F> x0,
                    numeric::Fixed<F> v0, numeric::Fixed<F> a0) {
  using W = numeric::Wide<F>;
  d = FixedFrameData<FixedTmd<F, P>>{};
  for (int k = 0; k < 2 * P; ++k) {
    const std::size_t i = static_cast<std::size_t>(k);
    W sum = W::from_raw(wide_product(x0, m.init_x[i]));
    sum += W::from_raw(wide_product(v0, m.init_v[i]));
    d.z(k) = sum.template to_fixed<F>();
  }
  d.a_prev = a0;
}

// A step's end: E_e (each story's drift a wide dot product over the
// blocks, then (1/2) k_i d_i^2 h in a 64-bit sum) and the top floor's peaks.
template <int F, int P>
void fixed_tmd_close(const FixedTmd<F, P>& m, FixedFrameData<FixedTmd<F, P>>& d) {
  using Q = numeric::Fixed<F>;
  for (std::size_t i = 0; i < static_cast<std::size_t>(P - 1); ++i) {
    const Q di = gain_dot<Q>(m.drift[i], d.z);
    d.ee.add_product(di, di * m.ee[i]);
  }
  const Q xt = abs(gain_dot<Q>(m.top_x, d.z));
  if (xt > d.peak_top) {
    d.peak_top = xt;
    d.peak_step = d.steps;
  }
  const Q vt = abs(gain_dot<Q>(m.top_v, d.z));
  if (vt > d.peak_top_velocity) d.peak_top_velocity = vt;
}

// One sensor step to the sample a1 [sa]: the blocks' exact step, then the
// readouts.
template <int F, int P>
void fixed_tmd_step(const FixedTmd<F, P>& m, FixedFrameData<FixedTmd<F, P>>& d, numeric::Fixed<F> a1) {
  m.lti.step(d.z, d.a_prev, a1);
  d.a_prev = a1;
  ++d.steps;
  fixed_tmd_close(m, d);
}

}  // namespace vines::fixed
