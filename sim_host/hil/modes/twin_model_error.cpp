#include "sim_host/hil/modes/twin_model_error.hpp"

#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "vines/numeric/expm.hpp"

namespace vines::host {
namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

constexpr double kStep = 0.005;     // the simulation's period [s]: 100 Hz of band, above the frame's modes
constexpr double kDuration = 60.0;  // of white ground acceleration
constexpr double kDelta = 1e-4;     // the log factors' central differences

// The frame with log factors th (stories' stiffness, then floors' masses) as
// x+ = Phi x + Gam w (w held over the step), y = Cy x: floors' relative
// displacements and velocities; y the sensors' absolute accelerations.
struct NoiseModel {
  Mat Phi, Cy;
  Vec Gam;
};

NoiseModel model(const HostFrame& f, double cd, const std::vector<int>& sensors, const Vec& th) {
  const int n = f.n;
  Mat K = Mat::Zero(n, n), C(n, n);
  for (int j = 0; j < n; ++j) {
    const double k = f.k[static_cast<std::size_t>(j)] * std::exp(th(j));
    K(j, j) += k;
    if (j > 0) K(j - 1, j - 1) += k, K(j - 1, j) -= k, K(j, j - 1) -= k;
  }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) C(i, j) = cd > 0 ? cd * K(i, j) : f.C_at(i, j);
  Vec minv(n);
  for (int i = 0; i < n; ++i) minv(i) = 1.0 / (f.m[static_cast<std::size_t>(i)] * std::exp(th(n + i)));
  Mat Z = Mat::Zero(2 * n + 1, 2 * n + 1);
  Z.block(0, n, n, n) = Mat::Identity(n, n);
  Z.block(n, 0, n, n) = -(minv.asDiagonal() * K);
  Z.block(n, n, n, n) = -(minv.asDiagonal() * C);
  Z.block(n, 2 * n, n, 1).setConstant(-1.0);
  Mat rows(static_cast<int>(sensors.size()), 2 * n);
  for (std::size_t s = 0; s < sensors.size(); ++s) rows.row(static_cast<int>(s)) = Z.block(n + sensors[s] - 1, 0, 1, 2 * n);
  const Mat e = numeric::expm(Mat(Z * kStep));
  return {e.topLeftCorner(2 * n, 2 * n), rows, e.block(0, 2 * n, 2 * n, 1)};
}

}  // namespace

Eigen::MatrixXd mass_effect_covariance(const HostFrame& f, double damping_s, const std::vector<int>& sensors,
                                       double mass_tolerance) {
  const int n = f.n, np = 2 * n, ny = static_cast<int>(sensors.size());
  // The nominal model and each log factor's two neighbours, stepped in turn
  // on the same noise.
  std::vector<NoiseModel> models;
  std::vector<Vec> x;
  for (int p = -1; p < np; ++p)
    for (double sign : {1.0, -1.0}) {
      if (p < 0 && sign < 0) continue;
      Vec th = Vec::Zero(np);
      if (p >= 0) th(p) = sign * kDelta;
      models.push_back(model(f, damping_s, sensors, th));
      x.push_back(Vec::Zero(2 * n));
    }
  std::mt19937_64 rng(20261128);
  std::normal_distribution<double> unit;
  std::vector<Mat> J(static_cast<std::size_t>(ny), Mat::Zero(np, np));  // per channel
  Vec ms = Vec::Zero(ny);
  Mat psi(np, ny);
  const auto steps = static_cast<long>(kDuration / kStep);
  for (long k = 0; k < steps; ++k) {
    const double w = unit(rng);
    for (std::size_t i = 0; i < models.size(); ++i) x[i] = models[i].Phi * x[i] + models[i].Gam * w;
    const Vec y0 = models[0].Cy * x[0];
    ms += y0.cwiseAbs2();
    for (int p = 0; p < np; ++p) {
      const auto a = static_cast<std::size_t>(1 + 2 * p);
      psi.row(p) = ((models[a].Cy * x[a] - models[a + 1].Cy * x[a + 1]) / (2 * kDelta)).transpose();
    }
    for (int c = 0; c < ny; ++c) J[static_cast<std::size_t>(c)].noalias() += psi.col(c) * psi.col(c).transpose();
  }
  // The information with each channel's noise in proportion to its RMS (a
  // share of it, as the bench's --measure-noise-pct; the share cancels).
  Mat F = Mat::Zero(np, np);
  for (int c = 0; c < ny; ++c) F += J[static_cast<std::size_t>(c)] / ms(c);
  const Mat A = F.topLeftCorner(n, n).ldlt().solve(F.topRightCorner(n, n));
  const Mat S = A * A.transpose() * (mass_tolerance * mass_tolerance / 3.0);
  return 0.5 * (S + S.transpose());
}

}  // namespace vines::host
