#include "sim_host/hil/modes/twin_design.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/LU>

#include "sim_host/hil/modes/twin_model_error.hpp"
#include "sim_host/scene/frame.hpp"
#include "vines/bytes/wire.hpp"
#include "vines/numeric/expm.hpp"
#include "vines/twin/image.hpp"

namespace vines::host {
namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using twin::TwinDims;
using twin::TwinExtra;

// The continuous model of docs/twin.md section 2: DOFs q (floors, then the
// TMD), state z = (q, q', f), z' = A z + Bg a_g + sum_j E_j p_j w_j; floor
// accelerations y = Cy z + sum_j Hy_j p_j w_j; parameter j's signal
// w_j = W_j z.
struct Continuous {
  TwinDims d;
  Mat A, E, Cy, Hy, W;  // E: nx x np, Cy: nq x nx (every DOF's absolute acceleration), Hy: nq x np, W: np x nx
  Vec Bg, prior_sd;
  std::vector<twin::TwinParam> kind;
  int device = -1;        // the force's DOF (VI NES)
  double device_mass = 1;
};

Continuous continuous(const SceneParams& p, const ModelInfo& info, int ny, const TwinTuning& t) {
  const HostFrame f = build_host_frame(p.frame);
  const int n = f.n;
  const DeviceKind kind = p.device.kind;
  const TwinExtra extra = kind == DeviceKind::kTmd ? TwinExtra::kTmd
                          : kind == DeviceKind::kVines ? TwinExtra::kForce
                                                       : TwinExtra::kNone;
  Continuous c;
  c.d = twin::twin_dims(n, extra, ny);
  const int nq = c.d.nq, nx = c.d.nx, np = c.d.np;
  const int dfloor = info.device_floor - 1;
  Mat K = Mat::Zero(nq, nq), C = Mat::Zero(nq, nq);
  Vec m(nq);
  for (int i = 0; i < n; ++i) {
    m(i) = f.m[static_cast<std::size_t>(i)];
    for (int j = 0; j < n; ++j) K(i, j) = f.K_at(i, j), C(i, j) = f.C_at(i, j);
  }
  // Springs: story j links floor j-1 (or the ground) and floor j, with
  // stiffness-proportional damping its rate too; the TMD's links its floor
  // and its mass.
  struct Spring {
    int a, b;
    double k, cd;
  };
  std::vector<Spring> springs;
  const double cd = p.frame.damping == DampingRule::kStiffnessProportional ? p.frame.stiffness_damping_s : 0.0;
  for (int j = 0; j < n; ++j) springs.push_back({j - 1, j, f.k[static_cast<std::size_t>(j)], cd});
  if (extra == TwinExtra::kTmd) {
    const TmdDesign& td = info.tmd;
    m(n) = td.mass;
    K(dfloor, dfloor) += td.k, K(n, n) += td.k, K(dfloor, n) -= td.k, K(n, dfloor) -= td.k;
    C(dfloor, dfloor) += td.c, C(n, n) += td.c, C(dfloor, n) -= td.c, C(n, dfloor) -= td.c;
    springs.push_back({dfloor, n, td.k, 0.0});
  }
  const Vec minv = m.cwiseInverse();
  c.A = Mat::Zero(nx, nx);
  c.A.block(0, nq, nq, nq) = Mat::Identity(nq, nq);
  c.A.block(nq, 0, nq, nq) = -(minv.asDiagonal() * K);
  c.A.block(nq, nq, nq, nq) = -(minv.asDiagonal() * C);
  c.Bg = Vec::Zero(nx);
  c.Bg.segment(nq, nq).setConstant(-1.0);
  c.Cy = Mat::Zero(nq, nx);
  c.Cy.leftCols(2 * nq) = c.A.block(nq, 0, nq, 2 * nq);
  if (extra == TwinExtra::kForce) {
    c.device = dfloor;
    c.device_mass = m(dfloor);
    c.A(nq + dfloor, 2 * nq) = 1.0;  // the force state is the force over the floor's mass
    c.A(2 * nq, 2 * nq) = -1.0 / t.force_tau_s;
    c.Cy(dfloor, 2 * nq) = 1.0;
  }
  // Spring j's loss p_j adds the force p_j k_j w_j g_j (g_j = e_b - e_a,
  // w_j its drift) to the DOFs; floor i's mass factor 1 - p_i the force
  // p_i m_i a_i (a_i its absolute acceleration).
  c.E = Mat::Zero(nx, np);
  c.Hy = Mat::Zero(nq, np);
  c.W = Mat::Zero(np, nx);
  c.prior_sd = Vec::Zero(np);
  for (std::size_t j = 0; j < springs.size(); ++j) {
    const Spring& s = springs[j];
    const int col = static_cast<int>(j);
    Vec g = Vec::Zero(nq);
    g(s.b) += 1.0;
    if (s.a >= 0) g(s.a) -= 1.0;
    const Vec acc = minv.asDiagonal() * g * s.k;
    c.E.col(col).segment(nq, nq) = acc;
    c.Hy.col(col) = acc;
    c.W.row(col).segment(0, nq) = g.transpose();
    c.W.row(col).segment(nq, nq) = s.cd * g.transpose();
    c.kind.push_back(col < n ? twin::TwinParam::kStory : twin::TwinParam::kDeviceSpring);
    c.prior_sd(col) = t.prior_sd;
  }
  // A VI NES's floor: its mass, which a stuck sphere adds to (the prior
  // spans the sphere's mass).
  if (extra == TwinExtra::kForce) {
    const int col = n;
    c.E(nq + dfloor, col) = 1.0;
    c.Hy(dfloor, col) = 1.0;
    c.W.row(col) = c.Cy.row(dfloor);
    c.kind.push_back(twin::TwinParam::kMass);
    c.prior_sd(col) = info.vines.mass / m(dfloor);
  }
  return c;
}

// Exact discretisation at h (Van Loan): Phi, the ground acceleration's
// first-order hold (B0, B1), each damage input's zero-order hold (G).
struct Discrete {
  Mat Phi, G;
  Vec B0, B1;
};

Discrete discretise(const Continuous& c, double h) {
  const int nx = c.d.nx, np = c.d.np, m = nx + 2 + np;
  Mat Z = Mat::Zero(m, m);
  Z.topLeftCorner(nx, nx) = c.A * h;
  Z.block(0, nx, nx, 1) = c.Bg * h;
  Z(nx, nx + 1) = 1.0;
  Z.block(0, nx + 2, nx, np) = c.E * h;
  const Mat e = numeric::expm(Z);
  Discrete d;
  d.Phi = e.topLeftCorner(nx, nx);
  const Vec g1 = e.block(0, nx, nx, 1), g2 = e.block(0, nx + 1, nx, 1);
  d.B0 = g1 - g2;
  d.B1 = g2;
  d.G = e.block(0, nx + 2, nx, np);
  return d;
}

// The filter's Riccati equation P = A P A' - A P C' (C P C' + R)^-1 C P A' + Q
// by the structure-preserving doubling algorithm (Chu, Fan and Lin 2005) on
// its dual; the prior covariance P. Throws if it does not converge.
Mat riccati(const Mat& A, const Mat& Cm, const Mat& Q, const Mat& R) {
  const int n = static_cast<int>(A.rows());
  const Mat I = Mat::Identity(n, n);
  Mat Ak = A.transpose(), Gk = Cm.transpose() * R.inverse() * Cm, Hk = Q;
  for (int it = 0; it < 200; ++it) {
    const Eigen::PartialPivLU<Mat> w(I + Gk * Hk);
    const Mat wA = w.solve(Ak), wG = w.solve(Gk);
    const Mat Hn = Hk + Ak.transpose() * Hk * wA;
    Gk = Gk + Ak * wG * Ak.transpose();
    Ak = Ak * wA;
    const double change = (Hn - Hk).norm(), size = Hn.norm();
    Hk = 0.5 * (Hn + Hn.transpose());
    if (!std::isfinite(size)) break;
    if (change <= 1e-13 * size) return Hk;
  }
  throw std::runtime_error("the twin's Kalman gain: the Riccati equation did not converge");
}

}  // namespace

// By bisection on the survival function, exact for whole k (y = x / 2):
// e^-y sum_i<m y^i / i! (k = 2m); erfc(sqrt y) + e^-y sum_i<m y^(i+1/2) /
// Gamma(i + 3/2) (k = 2m + 1).
double chi_square_quantile(int k, double tail) {
  if (!(tail > 0 && tail < 1)) throw std::runtime_error("--twin-fit-tail: a tail probability, above 0 and below 1");
  if (k < 1) return 0;
  auto survival = [k](double x) {
    const double y = x / 2;
    double sum = 0, term = 1;
    if (k % 2 == 0) {
      for (int i = 0; i < k / 2; ++i) sum += term, term *= y / (i + 1);
      return std::exp(-y) * sum;
    }
    term = std::sqrt(y) / (std::sqrt(M_PI) * 0.5);
    for (int i = 0; i < k / 2; ++i) sum += term, term *= y / (i + 1.5);
    return std::erfc(std::sqrt(y)) + std::exp(-y) * sum;
  };
  double lo = 0, hi = 10.0 * k + 200;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (survival(mid) > tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TwinDesign design_twin(const SceneParams& p, const ModelInfo& info, const std::vector<int>& sensors,
                       const std::vector<double>& noise_sd, const TwinTuning& t, const TwinBaselineStats* baseline) {
  const int ny = static_cast<int>(sensors.size());
  if (ny < 1 || ny > twin::kMaxSensors) throw std::runtime_error("--sensors: 1 to 8 floors");
  const double h = 1.0 / p.loop.sensor_rate_hz;
  const Continuous c = continuous(p, info, ny, t);
  const TwinDims& d = c.d;
  const int nq = d.nq, nx = d.nx, np = d.np;
  const Discrete z = discretise(c, h);
  // The sensors' rows.
  Mat Cm(ny, nx), Hm(ny, np);
  for (int i = 0; i < ny; ++i) Cm.row(i) = c.Cy.row(sensors[static_cast<std::size_t>(i)] - 1),
                               Hm.row(i) = c.Hy.row(sensors[static_cast<std::size_t>(i)] - 1);
  // Noises: the model's missed accelerations on every DOF's velocity over a
  // period, the force's AR(1) drive, the sensors'.
  Mat Q = Mat::Zero(nx, nx);
  for (int i = 0; i < nq; ++i) Q(nq + i, nq + i) = std::pow(t.model_accel_sd * h, 2);
  if (d.extra == TwinExtra::kForce) {
    const double rho = std::exp(-h / t.force_tau_s);
    Q(2 * nq, 2 * nq) = t.force_sd_mps2 * t.force_sd_mps2 * (1 - rho * rho);
  }
  Mat R = Mat::Zero(ny, ny);
  for (int i = 0; i < ny; ++i) R(i, i) = std::pow(std::max(noise_sd[static_cast<std::size_t>(i)], 1e-4), 2);
  TwinDesign out;
  // Two gains for a VI NES: the force free (impacts) and held near zero
  // (flight, most of the time); one otherwise.
  const Mat P = riccati(z.Phi, Cm, Q, R);
  Mat Qq = Q;
  if (d.extra == TwinExtra::kForce) Qq(2 * nq, 2 * nq) *= t.quiet_force_share * t.quiet_force_share;
  const Mat Pq = d.extra == TwinExtra::kForce ? riccati(z.Phi, Cm, Qq, R) : P;
  const Mat L = P * Cm.transpose() * (Cm * P * Cm.transpose() + R).inverse();
  const Mat S = Cm * Pq * Cm.transpose() + R;
  const Mat Lq = Pq * Cm.transpose() * S.inverse();
  const Mat Ppost = (Mat::Identity(nx, nx) - Lq * Cm) * Pq;
  out.roof_sd_m = std::sqrt(std::max(0.0, Ppost(d.stories - 1, d.stories - 1)));
  for (int i = 0; i < ny; ++i) out.innovation_sd.push_back(std::sqrt(S(i, i)));
  if (!L.allFinite() || !Lq.allFinite()) throw std::runtime_error("the twin's Kalman gain is not finite");

  // The image.
  std::vector<std::uint8_t> buf(twin::twin_header_bytes(d) + 8 * twin::twin_values(d));
  link::Writer w(buf.data(), buf.size());
  w.bytes(twin::kTwinMagic, 4);
  w.u16(twin::kTwinVersion);
  for (int v : {d.stories, static_cast<int>(d.extra), ny, np, nx, nq, c.device < 0 ? 255 : c.device})
    w.u8(static_cast<std::uint8_t>(v));
  for (int s : sensors) w.u8(static_cast<std::uint8_t>(s - 1));
  for (twin::TwinParam k : c.kind) w.u8(static_cast<std::uint8_t>(k));
  double set[twin::kTwinSettings] = {};
  set[twin::kForget] = std::exp(-h / t.memory_s);
  set[twin::kUpdateSteps] = std::max(1.0, std::round(t.update_s / h));
  set[twin::kKappa] = t.kappa;
  set[twin::kThreshold] = t.threshold;
  set[twin::kThresholdChange] = t.threshold_change;
  set[twin::kTwoStory] = t.two_story;
  set[twin::kTwoShare] = t.two_story_share;
  set[twin::kSeparation] = t.separation;
  set[twin::kInflation] = t.inflation;
  set[twin::kDriftVar] = t.drift_sd * t.drift_sd;
  set[twin::kSnapSteps] = std::max(1.0, std::round(t.snapshot_s / h));
  set[twin::kSuspect] = t.suspect;
  set[twin::kRestartSteps] = std::round(t.restart_gap_s / h);
  set[twin::kRestartKeep] = std::min(1.0, t.restart_keep);
  set[twin::kScoreForget] = std::exp(-set[twin::kUpdateSteps] * h / t.score_window_s);
  set[twin::kCalmSteps] = std::round(t.calm_s / h);
  set[twin::kMisfitLevel] = t.misfit_level;
  set[twin::kMisfitForget] = std::exp(-set[twin::kUpdateSteps] * h / t.misfit_memory_s);
  set[twin::kFitGate] = chi_square_quantile(d.stories - 1, t.fit_tail);
  set[twin::kBeforeVarMax] = t.before_sd_max * t.before_sd_max;
  set[twin::kDeviceLossMin] = t.device_loss_min;
  set[twin::kHoldSteps] = std::round(t.hold_s / h);
  set[twin::kInnovAlpha] = std::min(1.0, h / t.innov_window_s);
  set[twin::kForceScale] = c.device_mass;
  set[twin::kLossLow] = kTwinLossLow;
  set[twin::kLossHigh] = kTwinLossHigh;
  set[twin::kPeriod] = h;
  set[twin::kJumpSigma] = t.jump_sigma;
  set[twin::kJumpHold] = std::round(t.jump_hold_s / h);
  for (double v : set) w.f64(v);
  const Mat dA = z.Phi - Mat::Identity(nx, nx);
  const Vec top_c = c.Cy.row(d.stories - 1), top_h = c.Hy.row(d.stories - 1);
  auto put = [&](const Mat& m) {
    for (int r = 0; r < m.rows(); ++r)
      for (int col = 0; col < m.cols(); ++col) w.f64(m(r, col));
  };
  put(dA);
  put(z.B0.transpose());
  put(z.B1.transpose());
  put(z.G.transpose());
  put(c.W);
  put(L);
  put(Lq);
  put(Cm);
  put(Hm);
  put(top_c.transpose());
  put(top_h.transpose());
  // Each parameter's prior information and trust region (the stories' cap
  // scaled by its prior sd).
  put(c.prior_sd.cwiseAbs2().cwiseInverse().transpose());
  put((c.prior_sd * (t.max_step / t.prior_sd)).transpose());
  put(S.diagonal().transpose());
  // The decision's baseline and the model's error covariance of the stories.
  const int n = d.stories;
  Vec base = Vec::Zero(n);
  const double cd = p.frame.damping == DampingRule::kStiffnessProportional ? p.frame.stiffness_damping_s : 0.0;
  const Mat masses = mass_effect_covariance(build_host_frame(p.frame), cd, sensors, t.mass_tolerance);
  Mat sigma0 = masses + Mat::Identity(n, n) * (t.healthy_tolerance * t.healthy_tolerance / 3.0);
  if (baseline) {
    for (int a = 0; a < n; ++a) {
      base(a) = baseline->loss[static_cast<std::size_t>(a)];
      for (int b = 0; b < n; ++b) sigma0(a, b) = baseline->cov[static_cast<std::size_t>(a)][static_cast<std::size_t>(b)];
    }
    if (baseline->runs == 1) sigma0 += masses;
    sigma0 = 0.5 * (sigma0 + sigma0.transpose()).eval();
  }
  put(base.transpose());
  put(sigma0);
  if (!w.ok() || w.size() != buf.size()) throw std::runtime_error("the twin image: wrong size (a bug)");
  out.image = std::move(buf);
  return out;
}

}  // namespace vines::host
