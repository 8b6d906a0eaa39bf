// The twin image: what the host designs for a twin node's estimator
// (docs/twin.md) and sends in the configuration's model-image part, as it
// sends a core model image in replay mode and a hybrid frame image in hybrid
// mode. The node builds nothing: no eigensolver, no matrix exponential, no
// Riccati equation; it streams the image into its estimator's storage.
//
// Layout, little-endian (wire.hpp):
//   "VNTW", u16 version, u8 stories, u8 extra (TwinExtra), u8 ny, u8 np,
//   u8 nx, u8 nq, u8 device_dof (255: none), u8 sensor_dof[ny],
//   u8 kind[np] (TwinParam),
//   f64 settings[kTwinSettings] (TwinSetting order),
//   f64 dA[nx][nx], B0[nx], B1[nx], G[np][nx], W[np][nx], L[nx][ny],
//   Lq[nx][ny], C[ny][nx], H[ny][np], top_c[nx], top_h[np],
//   prior_info[np], step_cap[np], innovation_var[ny],
//   base[stories], sigma0[stories][stories]
// (L the gain with the device's force free, Lq with it held near zero: the
// same but for a VI NES; W_j the state's row that parameter j's force is
// proportional to; innovation_var the quiet design's)
// (matrices row-major: dA = Phi - I, the discrete transition less identity;
// see docs/twin.md for each).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vines/bytes/wire.hpp"
#include "vines/model/params.hpp"

namespace vines::twin {

// Floor accelerometers a twin node reads at most.
inline constexpr int kMaxSensors = 8;
inline constexpr std::uint8_t kNone8 = 255;  // "no device DOF"

inline constexpr std::uint8_t kTwinMagic[4] = {'V', 'N', 'T', 'W'};
inline constexpr std::uint16_t kTwinVersion = 6;

// The state beyond the frame's 2N: none (bare frame), the device's force on
// its floor as an unknown input (VI NES: one state), or the TMD's own mass
// (two states, its spring one more parameter).
enum class TwinExtra : std::uint8_t { kNone = 0, kForce = 1, kTmd = 2 };

// What a parameter p_j is: each scales its nominal by eta_j = 1 - p_j.
enum class TwinParam : std::uint8_t {
  kStory = 0,         // a story's stiffness (damage: p > 0 is a loss)
  kDeviceSpring = 1,  // the TMD's spring
  kMass = 2,          // the VI NES floor's mass: a sphere stuck on its floor adds its own
};

// Scalar settings of the estimator, in the image in this order.
enum TwinSetting : int {
  kForget,        // information kept per step (exp(-h / memory))
  kUpdateSteps,   // steps between parameter updates
  kKappa,         // the TMD spring is a candidate beyond kappa standard deviations...
  kThreshold,     // a story: one-story statistic of the absolute test (twin/decision.hpp)
  kDeviceLossMin, // ...and beyond this size (|loss|)
  kHoldSteps,     // a candidate held this long is an alarm
  kInnovAlpha,    // weight of a step in the innovations' running mean square
  kForceScale,    // device force state to N (the device floor's mass)
  kLossLow,       // estimates clamped to [low, high]
  kLossHigh,
  kPeriod,        // h [s]
  kJumpSigma,     // an innovation beyond this many quiet sd: the impact gain...
  kJumpHold,      // ...for this many steps
  kThresholdChange,  // one-story statistic of a change test
  kTwoStory,      // two stories: the pair's statistic beyond the best story's by this
  kSeparation,    // a story named: its statistic beyond the next story's by this
  kInflation,     // the estimate's covariance times this in the tests
  kDriftVar,      // a change test's model drift, variance per story
  kSnapSteps,     // steps between the decision's snapshots
  kSuspect,       // the score statistic beyond this restarts the information...
  kRestartSteps,  // ...at most once in this many steps...
  kRestartKeep,   // ...keeping this share of it
  kScoreForget,   // the score's memory per update (exp(-update / window))
  kCalmSteps,     // a change test leaves out this many steps after each impact (VI NES)
  kBeforeVarMax,  // a candidate onset: every story's fit before it within this variance
  kTwoShare,      // two stories: ...and beyond the best story's by this share of it
  kMisfitLevel,   // the score per parameter of a model that holds: beyond it, the misfit...
  kMisfitForget,  // ...held with this memory per update, scales the absolute test's estimate covariance
  kFitGate,       // the absolute test: what the best hypothesis leaves unexplained at most (chi-square)
  kTwinSettings
};

struct TwinDims {
  int stories = 0, nq = 0, nx = 0, np = 0, ny = 0;
  TwinExtra extra = TwinExtra::kNone;
};

// Dimensions of a twin of n stories with extra state e and ny sensors.
inline TwinDims twin_dims(int n, TwinExtra e, int ny) {
  TwinDims d;
  d.stories = n;
  d.extra = e;
  d.nq = n + (e == TwinExtra::kTmd ? 1 : 0);
  d.nx = 2 * d.nq + (e == TwinExtra::kForce ? 1 : 0);
  d.np = n + (e == TwinExtra::kNone ? 0 : 1);  // stories, then the TMD's spring or the VI NES floor's mass
  d.ny = ny;
  return d;
}

// Bytes before the matrices, and the number of f64 values after them.
inline std::size_t twin_header_bytes(const TwinDims& d) {
  return 4 + 2 + 7 + static_cast<std::size_t>(d.ny) + static_cast<std::size_t>(d.np);
}
inline std::size_t twin_values(const TwinDims& d) {
  const std::size_t x = d.nx, p = d.np, y = d.ny;
  const std::size_t n = d.stories;
  return kTwinSettings + x * x + 2 * x + 2 * p * x + 3 * x * y + y * p + x + 3 * p + y + n + n * n;
}
inline bool is_twin_image(const std::uint8_t* p, std::size_t n) {
  return p != nullptr && n >= 4 && std::memcmp(p, kTwinMagic, 4) == 0;
}

}  // namespace vines::twin
