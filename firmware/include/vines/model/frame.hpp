// The primary structure: an N-story shear frame (masses, story springs and
// dashpots in series), and its modal analysis. Built once, in double.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "vines/model/params.hpp"

namespace vines {

template <int N>
struct Frame {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  Vec m;   // floor masses [kg], bottom first
  Vec k;   // story stiffnesses [N/m] (damage already applied)
  Mat K;   // stiffness matrix
  Mat C;   // damping matrix
};

// Modal data of the undamped problem K phi = w^2 M phi. Mode shapes are
// mass-normalised (phi^T M phi = I) with a positive top-floor component.
template <int N>
struct Modal {
  using Vec = Eigen::Matrix<double, N, 1>;
  Vec omega;      // circular frequencies [rad/s], ascending
  Vec zeta;       // damping ratios phi_j^T C phi_j / (2 w_j)
  Vec gamma;      // participation factors phi_j^T M 1 [sqrt(kg)]
  Vec m_eff;      // effective modal masses gamma_j^2 [kg]; they sum to the total mass
  Eigen::Matrix<double, N, N> phi;  // columns: mode shapes
  Vec frequency_hz() const { return omega / (2.0 * 3.14159265358979323846); }
};

// Tridiagonal shear-frame matrix from story values c_1..c_N (story i links
// floor i-1 and floor i; floor 0 is the ground).
template <int N>
Eigen::Matrix<double, N, N> shear_matrix(const Eigen::Matrix<double, N, 1>& c) {
  Eigen::Matrix<double, N, N> out = Eigen::Matrix<double, N, N>::Zero();
  for (int i = 0; i < N; ++i) {
    out(i, i) = c(i) + (i + 1 < N ? c(i + 1) : 0.0);
    if (i + 1 < N) out(i, i + 1) = out(i + 1, i) = -c(i + 1);
  }
  return out;
}

// Undamped modes of (K, M) via the symmetric problem M^-1/2 K M^-1/2.
template <int N>
Modal<N> modal_analysis(const Frame<N>& f) {
  Modal<N> md;
  const typename Frame<N>::Vec inv_sqrt_m = f.m.cwiseSqrt().cwiseInverse();
  const Eigen::Matrix<double, N, N> a = inv_sqrt_m.asDiagonal() * f.K * inv_sqrt_m.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(a);
  md.omega = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  md.phi = inv_sqrt_m.asDiagonal() * es.eigenvectors();
  for (int j = 0; j < N; ++j) {
    if (md.phi(N - 1, j) < 0.0) md.phi.col(j) *= -1.0;
    md.gamma(j) = md.phi.col(j).dot(f.m);
    md.m_eff(j) = md.gamma(j) * md.gamma(j);
    md.zeta(j) = md.phi.col(j).dot(f.C * md.phi.col(j)) / (2.0 * md.omega(j));
  }
  return md;
}

// Masses, stiffnesses (times eta_k) and damping from the parameters. The
// parameters must have passed validate() and have f.stories == N.
template <int N>
Frame<N> build_frame(const FrameParams& p) {
  Frame<N> f;
  for (int i = 0; i < N; ++i) {
    f.m(i) = p.mass_kg[i];
    f.k(i) = story_stiffness(p, i);
  }
  f.K = shear_matrix<N>(f.k);
  f.C.setZero();
  switch (p.damping) {
    case DampingRule::kStiffnessProportional:
      f.C = p.stiffness_damping_s * f.K;
      break;
    case DampingRule::kRayleigh: {
      // zeta_i = a0 / (2 w_i) + a1 w_i / 2 on the two named modes.
      const Modal<N> md = modal_analysis(f);
      const double wi = md.omega(p.rayleigh_modes[0] - 1), wj = md.omega(p.rayleigh_modes[1] - 1);
      const double zi = p.rayleigh_zeta[0], zj = p.rayleigh_zeta[1];
      const double a1 = 2.0 * (zj * wj - zi * wi) / (wj * wj - wi * wi);
      const double a0 = 2.0 * zi * wi - a1 * wi * wi;
      f.C = a0 * f.m.asDiagonal().toDenseMatrix() + a1 * f.K;
      break;
    }
    case DampingRule::kModal: {
      // C = M Phi diag(2 zeta w) Phi^T M: every mode gets the same ratio.
      const Modal<N> md = modal_analysis(f);
      const Eigen::Matrix<double, N, N> mphi = f.m.asDiagonal() * md.phi;
      f.C = mphi * (2.0 * p.modal_zeta * md.omega).asDiagonal() * mphi.transpose();
      break;
    }
  }
  return f;
}

}  // namespace vines
