// The twin image (twin/image.hpp) streamed into a twin node: the decoder
// that Estimator (twin/estimator.hpp) is built on. It checks the header, the
// dimensions against the node's capacity N, every value finite, and the
// settings in range; what it decodes (the discrete model, the gains, the
// damage patterns, the settings) the estimator reads as its own.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vines/twin/image.hpp"

namespace vines::twin {

template <typename S, int N>
class ImageDecoder {
 public:
  static constexpr int kQ = N + 1, kX = 2 * N + 2, kP = N + 1, kY = kMaxSensors;

  // ---- the image, streamed -------------------------------------------------
  void image_begin() {
    pos_ = 0;
    value_ = 0;
    nbyte_ = 0;
    ready_ = false;
    failed_ = nullptr;
  }
  const char* image_push(const std::uint8_t* p, std::size_t n) {
    for (std::size_t i = 0; i < n && !failed_; ++i) byte(p[i]);
    return failed_;
  }
  const char* image_finish() {
    if (failed_) return failed_;
    if (pos_ < 4 + 2 + 7 || value_ != twin_values(d_) || nbyte_ != 0) return "twin image: truncated";
    if (const char* why = check()) return why;
    ready_ = true;
    return nullptr;
  }
  bool ready() const { return ready_; }
  const TwinDims& dims() const { return d_; }
  double period() const { return set_[kPeriod]; }
  int sensor_floor(int i) const { return sensor_[i] + 1; }

 protected:
  // ---- image decoding ------------------------------------------------------
  void byte(std::uint8_t b) {
    const std::size_t fixed = 4 + 2 + 7;
    if (pos_ < fixed) return header(b);
    if (pos_ < twin_header_bytes(d_)) return index(b);
    raw_ |= static_cast<std::uint64_t>(b) << (8 * nbyte_);
    ++pos_;
    if (++nbyte_ < 8) return;
    double v;
    std::memcpy(&v, &raw_, 8);
    raw_ = 0;
    nbyte_ = 0;
    if (value_ >= twin_values(d_)) {
      failed_ = "twin image: longer than its dimensions";
      return;
    }
    if (!std::isfinite(v)) {
      failed_ = "twin image: a value is not finite";
      return;
    }
    put(value_++, v);
  }
  void header(std::uint8_t b) {
    const std::size_t i = pos_++;
    if (i < 4) {
      if (b != kTwinMagic[i]) failed_ = "twin image: not a twin image";
      if (i == 0) raw_ = 0, nbyte_ = 0, value_ = 0;
      return;
    }
    if (i == 4) ver_ = b;
    if (i == 5 && (ver_ | b << 8) != kTwinVersion) failed_ = "twin image: another version";
    if (i == 6) d_.stories = b;
    if (i == 7) {
      if (b > static_cast<std::uint8_t>(TwinExtra::kTmd)) failed_ = "twin image: unknown device state";
      d_.extra = static_cast<TwinExtra>(b);
    }
    if (i == 8) d_.ny = b;
    if (i == 9) d_.np = b;
    if (i == 10) d_.nx = b;
    if (i == 11) d_.nq = b;
    if (i == 12) {
      device_dof_ = b;
      const TwinDims e = twin_dims(d_.stories, d_.extra, d_.ny);
      if (d_.stories < 1 || d_.stories > N) failed_ = "twin image: more stories than this node holds";
      else if (d_.ny < 1 || d_.ny > kY) failed_ = "twin image: 1 to 8 sensors";
      else if (e.nq != d_.nq || e.nx != d_.nx || e.np != d_.np) failed_ = "twin image: inconsistent dimensions";
    }
  }
  void index(std::uint8_t b) {
    const std::size_t i = pos_++ - (4 + 2 + 7);
    const std::size_t y = d_.ny;
    if (i < y) sensor_[i] = b;
    else kind_[i - y] = b;
  }
  // The v-th value after the header, into its place.
  void put(std::size_t v, double x) {
    const std::size_t nx = d_.nx, np = d_.np, ny = d_.ny, n = d_.stories;
    const S s = static_cast<S>(x);
    std::size_t o = kTwinSettings;
    if (v < o) {
      set_[v] = x;
      return;
    }
    auto in = [&](std::size_t count) {
      const bool here = v < o + count;
      if (!here) o += count;
      return here;
    };
    if (in(nx * nx)) dA_[(v - o) / nx][(v - o) % nx] = s;
    else if (in(nx)) B0_[v - o] = s;
    else if (in(nx)) B1_[v - o] = s;
    else if (in(np * nx)) G_[(v - o) / nx][(v - o) % nx] = s;
    else if (in(np * nx)) W_[(v - o) / nx][(v - o) % nx] = s;
    else if (in(nx * ny)) L_[(v - o) / ny][(v - o) % ny] = s;
    else if (in(nx * ny)) Lq_[(v - o) / ny][(v - o) % ny] = s;
    else if (in(ny * nx)) C_[(v - o) / nx][(v - o) % nx] = s;
    else if (in(ny * np)) H_[(v - o) / np][(v - o) % np] = s;
    else if (in(nx)) top_c_[v - o] = s;
    else if (in(np)) top_h_[v - o] = s;
    else if (in(np)) prior_[v - o] = s;
    else if (in(np)) cap_[v - o] = s;
    else if (in(ny)) var_[v - o] = s;
    else if (in(n)) base_[v - o] = s;
    else sigma0_[(v - o) / n][(v - o) % n] = s;
  }
  // The decoded image's indices and settings make sense for this node.
  const char* check() {
    for (int i = 0; i < d_.ny; ++i)
      if (sensor_[i] >= d_.stories) return "twin image: a sensor off the frame";
    for (int j = 0; j < d_.np; ++j)
      if (kind_[j] > static_cast<std::uint8_t>(TwinParam::kMass) || !(prior_[j] > S(0)) || !(cap_[j] > S(0)))
        return "twin image: a parameter's kind, prior or step out of range";
    if (d_.extra == TwinExtra::kForce && device_dof_ >= d_.stories) return "twin image: the device floor is off the frame";
    const double* c = set_;
    if (!(c[kForget] > 0 && c[kForget] <= 1) || !(c[kUpdateSteps] >= 1 && c[kUpdateSteps] <= 1e6) ||
        !(c[kKappa] >= 0) || !(c[kThreshold] > 0) || !(c[kDeviceLossMin] >= 0) || !(c[kHoldSteps] >= 0) ||
        !(c[kInnovAlpha] > 0 && c[kInnovAlpha] <= 1) || !(c[kLossLow] < 0 && c[kLossHigh] > 0 && c[kLossHigh] < 1) ||
        !(c[kPeriod] > 0) || !(c[kJumpSigma] > 0) || !(c[kJumpHold] >= 0) || !(c[kThresholdChange] > 0) ||
        !(c[kTwoStory] >= 0) || !(c[kSeparation] >= 0) || !(c[kInflation] > 0) || !(c[kDriftVar] >= 0) ||
        !(c[kSnapSteps] >= 1 && c[kSnapSteps] <= 1e6) || !(c[kSuspect] > 0) || !(c[kRestartSteps] >= 0) ||
        !(c[kRestartKeep] > 0 && c[kRestartKeep] <= 1) || !(c[kScoreForget] >= 0 && c[kScoreForget] < 1) ||
        !(c[kCalmSteps] >= 0 && c[kCalmSteps] <= 1e6) || !(c[kBeforeVarMax] > 0) ||
        !(c[kTwoShare] >= 0) || !(c[kMisfitLevel] > 0) || !(c[kMisfitForget] >= 0 && c[kMisfitForget] < 1) ||
        !(c[kFitGate] >= 0))
      return "twin image: a setting out of range";
    // The model's covariance: symmetric with a positive diagonal (the tests
    // add it to a positive definite one).
    for (int a = 0; a < d_.stories; ++a) {
      if (!(sigma0_[a][a] >= S(0))) return "twin image: the model's covariance has a negative variance";
      for (int b = 0; b < a; ++b)
        if (!(sigma0_[a][b] == sigma0_[b][a])) return "twin image: the model's covariance is not symmetric";
    }
    for (int i = 0; i < d_.ny; ++i)
      if (!(var_[i] > S(0))) return "twin image: an innovation variance is not positive";
    update_steps_ = static_cast<long>(c[kUpdateSteps]);
    hold_steps_ = static_cast<long>(c[kHoldSteps]);
    return nullptr;
  }

  TwinDims d_;
  std::size_t pos_ = 0, value_ = 0;
  int nbyte_ = 0;
  std::uint64_t raw_ = 0;
  std::uint8_t ver_ = 0, device_dof_ = kNone8;
  const char* failed_ = nullptr;
  bool ready_ = false;
  double set_[kTwinSettings] = {};
  std::uint8_t sensor_[kY] = {}, kind_[kP] = {};
  S dA_[kX][kX] = {}, B0_[kX] = {}, B1_[kX] = {}, G_[kP][kX] = {}, W_[kP][kX] = {};
  S L_[kX][kY] = {}, Lq_[kX][kY] = {}, C_[kY][kX] = {};
  S H_[kY][kP] = {}, top_c_[kX] = {}, top_h_[kP] = {}, prior_[kP] = {}, cap_[kP] = {}, var_[kY] = {};
  S base_[N] = {}, sigma0_[N][N] = {};
  long update_steps_ = 1, hold_steps_ = 0;
};

}  // namespace vines::twin
