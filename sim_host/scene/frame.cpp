#include "sim_host/scene/frame.hpp"

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace vines::host {
namespace {

// Run-time size with a compile-time cap: no heap (the firmware defines EIGEN_NO_MALLOC).
using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStories, kMaxStories>;
using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxStories, 1>;

Mat to_mat(const std::vector<double>& a, int n) {
  Mat out(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) out(i, j) = a[static_cast<std::size_t>(i * n + j)];
  return out;
}

void from_mat(const Mat& m, std::vector<double>* a) {
  const int n = static_cast<int>(m.rows());
  a->assign(static_cast<std::size_t>(n * n), 0.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) (*a)[static_cast<std::size_t>(i * n + j)] = m(i, j);
}

// Mass-normalised undamped modes, ascending, positive top-floor component.
void modes(const HostFrame& f, Vec* omega, Mat* phi) {
  const int n = f.n;
  Vec inv_sqrt_m(n);
  for (int i = 0; i < n; ++i) inv_sqrt_m(i) = 1.0 / std::sqrt(f.m[static_cast<std::size_t>(i)]);
  const Mat a = inv_sqrt_m.asDiagonal() * to_mat(f.K, n) * inv_sqrt_m.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Mat> es(a);
  *omega = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  *phi = inv_sqrt_m.asDiagonal() * es.eigenvectors();
  for (int j = 0; j < n; ++j)
    if ((*phi)(n - 1, j) < 0.0) phi->col(j) *= -1.0;
}

}  // namespace

HostFrame build_host_frame(const FrameParams& p) {
  HostFrame f;
  const int n = p.stories;
  f.n = n;
  for (int i = 0; i < n; ++i) {
    f.m.push_back(p.mass_kg[i]);
    f.k.push_back(story_stiffness(p, i));
  }
  // Tridiagonal shear matrix: story i links floor i-1 and floor i.
  f.K.assign(static_cast<std::size_t>(n * n), 0.0);
  for (int i = 0; i < n; ++i) {
    const std::size_t ii = static_cast<std::size_t>(i);
    f.K[ii * n + ii] = f.k[ii] + (i + 1 < n ? f.k[ii + 1] : 0.0);
    if (i + 1 < n) f.K[ii * n + ii + 1] = f.K[(ii + 1) * n + ii] = -f.k[ii + 1];
  }
  const Mat K = to_mat(f.K, n);
  Mat C = Mat::Zero(n, n);
  switch (p.damping) {
    case DampingRule::kStiffnessProportional:
      C = p.stiffness_damping_s * K;
      break;
    case DampingRule::kRayleigh: {
      Vec omega;
      Mat phi;
      modes(f, &omega, &phi);
      const double wi = omega(p.rayleigh_modes[0] - 1), wj = omega(p.rayleigh_modes[1] - 1);
      const double zi = p.rayleigh_zeta[0], zj = p.rayleigh_zeta[1];
      const double a1 = 2.0 * (zj * wj - zi * wi) / (wj * wj - wi * wi);
      const double a0 = 2.0 * zi * wi - a1 * wi * wi;
      Vec m(n);
      for (int i = 0; i < n; ++i) m(i) = f.m[static_cast<std::size_t>(i)];
      C = a0 * Mat(m.asDiagonal()) + a1 * K;
      break;
    }
    case DampingRule::kModal: {
      Vec omega;
      Mat phi;
      modes(f, &omega, &phi);
      Vec m(n);
      for (int i = 0; i < n; ++i) m(i) = f.m[static_cast<std::size_t>(i)];
      const Mat mphi = m.asDiagonal() * phi;
      C = mphi * Vec(2.0 * p.modal_zeta * omega).asDiagonal() * mphi.transpose();
      break;
    }
  }
  from_mat(C, &f.C);
  return f;
}

HostModes host_modes(const HostFrame& f) {
  Vec omega;
  Mat phi;
  modes(f, &omega, &phi);
  HostModes out;
  for (int j = 0; j < f.n; ++j) {
    double gamma = 0.0;
    for (int i = 0; i < f.n; ++i) gamma += phi(i, j) * f.m[static_cast<std::size_t>(i)];
    out.omega.push_back(omega(j));
    out.m_eff.push_back(gamma * gamma);
  }
  return out;
}

}  // namespace vines::host
