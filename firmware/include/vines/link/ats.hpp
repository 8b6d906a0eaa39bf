// Adaptive time series (ATS) compensation of a shake table's delay and lag
// (Chae, Kazemibidokhti, Ricles, Earthquake Eng. Struct. Dyn. 42(11), 2013).
// The command is
//   u = a0 x_t + a1 x_t' + a2 x_t''
// of the target displacement x_t and its backward-difference derivatives. The
// coefficients are fitted online to the commands sent against the measured
// table displacement x_m at the same samples, u ~ a0 x_m + a1 x_m' + a2 x_m''
// (the actuator's inverse as the samples see it), by least squares weighted
// exp(-age / window), regularised towards the present coefficients with the
// weight of a table moving 0.1 mm at 1 Hz (a table at rest leaves them where
// they are), then clamped to bounds and rate limited per step. The fit sees
// u and x_m through the same low-pass (2 Hz, the band of the frame's
// response): a linear relation holds between the filtered signals too, and
// the polynomial, which cannot be the servo's inverse at every frequency, is
// fitted where the response is rather than to the content of impacts, which
// the servo does not follow (unfiltered, a VI NES's impacts pull a1 0.5 ms
// short on El Centro and the table stays 0.8 ms behind).
// Fixed memory, no heap: the same code runs on the host and on a board.
#pragma once

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace vines::link {

// Bounds of a0, a1 [s], a2 [s^2]: a gain from a half to double, a lead up to
// 100 ms and a second-order term up to 0.01 s^2 (a 1.6 Hz servo's 1 / w^2).
inline constexpr double kAtsLow[3] = {0.5, 0.0, 0.0};
inline constexpr double kAtsHigh[3] = {2.0, 0.1, 0.01};
// Largest change of each per second (per step: times h): a1 moves 20 ms in a
// second, a2 0.002 s^2.
inline constexpr double kAtsRate[3] = {0.5, 0.02, 0.002};
// The cut-off of the fit's low-pass [Hz].
inline constexpr double kAtsFitHz = 2.0;

// A second-order Butterworth low-pass (bilinear transform), direct form II
// transposed; start() sets it at rest on a constant input.
struct LowPass {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0, z1 = 0, z2 = 0;
  void design(double fc, double h) {
    const double k = std::tan(3.14159265358979323846 * fc * h), q = 1.4142135623730951;
    const double n = 1 / (1 + q * k + k * k);
    b0 = k * k * n, b1 = 2 * b0, b2 = b0;
    a1 = 2 * (k * k - 1) * n, a2 = (1 - q * k + k * k) * n;
  }
  void start(double x) {
    z1 = x - b0 * x;
    z2 = b2 * x - a2 * x;
  }
  double operator()(double x) {
    const double y = b0 * x + z1;
    z1 = b1 * x - a1 * y + z2;
    z2 = b2 * x - a2 * y;
    return y;
  }
};

class Ats {
 public:
  // Sample period h [s], the fit's memory (window) [s], the initial a1 (the
  // nominal delay estimate; a0 starts at 1, a2 at 0).
  void reset(double h, double window_s, double a1) {
    h_ = h;
    lp_u_.design(kAtsFitHz, h);
    lp_x_.design(kAtsFitHz, h);
    lambda_ = std::exp(-h / window_s);
    a_ << 1.0, clamp(a1, 1), 0.0;
    s_.setZero();
    b_.setZero();
    nt_ = nm_ = 0;
    // The regularisation: a table moving d = 0.1 mm at w = 1 Hz over the
    // window, each derivative's column at its scale (d, d w, d w^2).
    const double n = 1.0 / (1.0 - lambda_), d = 1e-4, w = 2 * 3.14159265358979323846;
    reg_ << n * d * d, n * d * d * w * w, n * d * d * w * w * w * w;
  }

  // One step: the target now and the table's measured displacement now
  // (non-finite: not measured; the fit waits for three measured samples in a
  // row again). Returns the command. The fit takes this step's command
  // against this step's measurement.
  double step(double target, double measured) {
    push(xt_, &nt_, target);
    const double u = a_.dot(derivatives(xt_));
    if (!std::isfinite(measured)) {
      nm_ = 0;
      return u;
    }
    if (nm_ == 0) lp_u_.start(u), lp_x_.start(measured);
    const double uf = lp_u_(u);
    push(xm_, &nm_, lp_x_(measured));
    if (nm_ >= 3) fit(uf, derivatives(xm_));
    return u;
  }

  double coefficient(int i) const { return a_[i]; }

 private:
  static double clamp(double v, int i) { return v < kAtsLow[i] ? kAtsLow[i] : v > kAtsHigh[i] ? kAtsHigh[i] : v; }

  // Newest first; the first sample fills the history (at rest before it).
  static void push(double* x, int* n, double v) {
    if (*n == 0) x[1] = x[2] = v;
    else x[2] = x[1], x[1] = x[0];
    x[0] = v;
    if (*n < 3) ++*n;
  }

  // (x, x', x'') by backward differences.
  Eigen::Vector3d derivatives(const double* x) const {
    return Eigen::Vector3d(x[0], (x[0] - x[1]) / h_, (x[0] - 2 * x[1] + x[2]) / (h_ * h_));
  }

  // The weighted sums take the new pair; the regularised normal equations
  // (scaled to a unit diagonal) give the fit, which the coefficients move
  // towards within their bounds and rates.
  void fit(double u, const Eigen::Vector3d& phi) {
    s_ = lambda_ * s_ + phi * phi.transpose();
    b_ = lambda_ * b_ + phi * u;
    Eigen::Matrix3d a = s_;
    a.diagonal() += reg_;
    const Eigen::Vector3d rhs = b_ + reg_.cwiseProduct(a_);
    const Eigen::Vector3d d = a.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::Matrix3d scaled = d.asDiagonal() * a * d.asDiagonal();
    const Eigen::Vector3d best = d.cwiseProduct(scaled.ldlt().solve(d.cwiseProduct(rhs)));
    if (!best.allFinite()) return;
    for (int i = 0; i < 3; ++i) {
      const double max_step = kAtsRate[i] * h_, want = clamp(best[i], i) - a_[i];
      a_[i] += want > max_step ? max_step : want < -max_step ? -max_step : want;
    }
  }

  double h_ = 1e-3, lambda_ = 0.999;
  Eigen::Vector3d a_ = Eigen::Vector3d(1, 0, 0), reg_ = Eigen::Vector3d::Zero(), b_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d s_ = Eigen::Matrix3d::Zero();
  LowPass lp_u_, lp_x_;             // the fit's view of the command and the measurement
  double xt_[3] = {}, xm_[3] = {};  // newest first (xm_: filtered)
  int nt_ = 0, nm_ = 0;             // samples in each history (3: full)
};

}  // namespace vines::link
