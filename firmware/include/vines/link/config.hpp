// The node's configuration: the scene's parameters (params.hpp) plus how the
// node runs them, serialised field by field into a blob that travels in
// CONFIGURE chunks. Decoding refuses out-of-range enums and counts; the
// model builder (validate.hpp) then checks the numbers themselves.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>

#include "vines/bytes/wire.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/params.hpp"

namespace vines::link {

// A twin node's estimator: none (the scene's model run open loop on the
// ground acceleration) or the Kalman filter with stiffness identification of
// twin/estimator.hpp (docs/twin.md).
enum class TwinEstimator : std::uint8_t { kNone, kKalman };

enum class NodeMode : std::uint8_t {
  kReplay,  // ground acceleration in, the scene's model out (bench mode)
  kTwin,    // digital twin: also measured top-floor acceleration in; residual and alarms out
  kHybrid,  // shake table: the bare frame with the measured device force in; table command out
};

// How a hybrid node compensates the table's delay: not at all (the command
// is the target), by polynomial extrapolation over comp_delay_s
// (extrapolate.hpp), or adaptively (ats.hpp, from a1 = comp_delay_s).
enum class CompKind : std::uint8_t { kNone, kPolynomial, kAdaptive };
inline constexpr std::uint8_t kCompKinds = 3;

struct NodeConfig {
  SceneParams scene;
  std::uint8_t scalar = 0;  // 0 double, 1 float, 2 Q3.28 fixed point
  NodeMode mode = NodeMode::kReplay;
  // Fault policy (docs/link_protocol.md):
  double sensor_range_mps2 = 0;  // |a| at or beyond it: saturated (0: no range)
  double grace_periods = 1.5;    // a sample is due at k h; missing after k h + grace h: held
  double stall_periods = 10;     // no frame for this long: a stall is reported
  // Twin:
  TwinEstimator estimator = TwinEstimator::kNone;  // kKalman: the model image is a twin image
  double drift_limit_m[kMaxStories] = {};  // per story (0: no alarm)
  double residual_limit_mps2 = 0;          // RMS residual alarm threshold (0: none)
  double residual_window_s = 1.0;          // time constant of the running RMS
  // Hybrid:
  CompKind comp_kind = CompKind::kPolynomial;  // any u8 decodes; validate_node checks it
  double comp_delay_s = 0;   // actuator delay compensated by extrapolating the command (adaptive: initial a1)
  std::uint8_t comp_order = 2;  // polynomial order of that extrapolation (1-3)
  double comp_window_s = 1;  // adaptive: memory of the fit (time constant of its forgetting)
  // Deadline monitor: a step whose model work takes more than this many of
  // the node's counter ticks is an overrun (0: one sensor period).
  std::uint32_t budget_ticks = 0;
};

inline constexpr std::size_t kMaxConfigBlob = 1800;

inline std::size_t encode(const NodeConfig& c, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  const FrameParams& f = c.scene.frame;
  const int n = f.stories;
  if (n < 1 || n > kMaxStories) return 0;
  w.u8(static_cast<std::uint8_t>(n));
  for (int i = 0; i < n; ++i) w.f64(f.mass_kg[i]);
  for (int i = 0; i < n; ++i) w.f64(f.stiffness_n_per_m[i]);
  for (int i = 0; i < n; ++i) w.f64(f.stiffness_scales[i]);
  w.u8(static_cast<std::uint8_t>(f.damping));
  for (double v : {f.stiffness_damping_s, f.rayleigh_zeta[0], f.rayleigh_zeta[1], f.modal_zeta, f.stiffness_scale})
    w.f64(v);
  w.u8(static_cast<std::uint8_t>(f.rayleigh_modes[0]));
  w.u8(static_cast<std::uint8_t>(f.rayleigh_modes[1]));
  const DeviceParams& d = c.scene.device;
  w.u8(static_cast<std::uint8_t>(d.kind));
  w.u8(static_cast<std::uint8_t>(d.floor));
  for (double v : {d.mass_ratio, d.mass_kg, d.tmd.k_n_per_m, d.tmd.c_ns_per_m, d.tmd.initial_position_m,
                   d.tmd.initial_velocity_mps})
    w.f64(v);
  const VinesParams& v = d.vines;
  for (double x : {v.radius_m, v.density_kg_m3, v.young_pa, v.poisson, v.wall_young_pa, v.wall_poisson, v.beta,
                   v.box_length_m, v.eps, v.v_ref_mps, v.tau_s, v.initial_position_m, v.initial_velocity_mps})
    w.f64(x);
  w.u8(static_cast<std::uint8_t>(v.law));
  w.u8(v.start_at_left_wall ? 1 : 0);
  const LoopParams& l = c.scene.loop;
  for (double x : {l.sensor_rate_hz, l.contact_rtol, l.contact_count_depth_m, l.divergence_limit_m}) w.f64(x);
  w.u32(static_cast<std::uint32_t>(l.max_substeps_per_step));
  w.u8(static_cast<std::uint8_t>((l.energy_ledger ? 1 : 0) | (l.floor_peaks ? 2 : 0)));
  w.u8(c.scalar);
  w.u8(static_cast<std::uint8_t>(c.mode));
  for (double x : {c.sensor_range_mps2, c.grace_periods, c.stall_periods, c.residual_limit_mps2,
                   c.residual_window_s, c.comp_delay_s})
    w.f64(x);
  w.u8(c.comp_order);
  for (int i = 0; i < n; ++i) w.f64(c.drift_limit_m[i]);
  w.u8(static_cast<std::uint8_t>(l.contact_scheme));
  w.u8(static_cast<std::uint8_t>(l.bounded_substeps));
  w.u16(static_cast<std::uint16_t>(l.split_steps));
  w.u32(c.budget_ticks);
  w.u8(static_cast<std::uint8_t>(c.comp_kind));
  w.f64(c.comp_window_s);
  w.u8(static_cast<std::uint8_t>(c.estimator));
  return w.ok() ? w.size() : 0;
}

// Decodes a blob; false if it is malformed (then *c is unspecified).
inline bool decode(const std::uint8_t* p, std::size_t len, NodeConfig* c) {
  Reader r(p, len);
  *c = NodeConfig{};
  FrameParams& f = c->scene.frame;
  const int n = r.u8();
  if (n < 1 || n > kMaxStories) return false;
  f.stories = n;
  for (int i = 0; i < n; ++i) f.mass_kg[i] = r.f64();
  for (int i = 0; i < n; ++i) f.stiffness_n_per_m[i] = r.f64();
  for (int i = 0; i < n; ++i) f.stiffness_scales[i] = r.f64();
  const std::uint8_t damping = r.u8();
  if (damping > static_cast<std::uint8_t>(DampingRule::kModal)) return false;
  f.damping = static_cast<DampingRule>(damping);
  for (double* v : {&f.stiffness_damping_s, &f.rayleigh_zeta[0], &f.rayleigh_zeta[1], &f.modal_zeta,
                    &f.stiffness_scale})
    *v = r.f64();
  f.rayleigh_modes[0] = r.u8();
  f.rayleigh_modes[1] = r.u8();
  DeviceParams& d = c->scene.device;
  const std::uint8_t kind = r.u8();
  if (kind > static_cast<std::uint8_t>(DeviceKind::kVines)) return false;
  d.kind = static_cast<DeviceKind>(kind);
  d.floor = r.u8();
  for (double* v : {&d.mass_ratio, &d.mass_kg, &d.tmd.k_n_per_m, &d.tmd.c_ns_per_m, &d.tmd.initial_position_m,
                    &d.tmd.initial_velocity_mps})
    *v = r.f64();
  VinesParams& v = d.vines;
  for (double* x : {&v.radius_m, &v.density_kg_m3, &v.young_pa, &v.poisson, &v.wall_young_pa, &v.wall_poisson,
                    &v.beta, &v.box_length_m, &v.eps, &v.v_ref_mps, &v.tau_s, &v.initial_position_m,
                    &v.initial_velocity_mps})
    *x = r.f64();
  const std::uint8_t law = r.u8();
  if (law >= kContactLawCount) return false;
  v.law = static_cast<ContactLaw>(law);
  v.start_at_left_wall = r.u8() != 0;
  LoopParams& l = c->scene.loop;
  for (double* x : {&l.sensor_rate_hz, &l.contact_rtol, &l.contact_count_depth_m, &l.divergence_limit_m}) *x = r.f64();
  const std::uint32_t cap = r.u32();
  if (cap > 1u << 24) return false;
  l.max_substeps_per_step = static_cast<int>(cap);
  const std::uint8_t outputs = r.u8();
  l.energy_ledger = (outputs & 1) != 0;
  l.floor_peaks = (outputs & 2) != 0;
  c->scalar = r.u8();
  const std::uint8_t mode = r.u8();
  if (c->scalar > 2 || mode > static_cast<std::uint8_t>(NodeMode::kHybrid)) return false;
  c->mode = static_cast<NodeMode>(mode);
  for (double* x : {&c->sensor_range_mps2, &c->grace_periods, &c->stall_periods, &c->residual_limit_mps2,
                    &c->residual_window_s, &c->comp_delay_s})
    *x = r.f64();
  c->comp_order = r.u8();
  for (int i = 0; i < n; ++i) c->drift_limit_m[i] = r.f64();
  const std::uint8_t scheme = r.u8(), substeps = r.u8();
  const std::uint16_t split = r.u16();
  if (scheme > static_cast<std::uint8_t>(ContactScheme::kSplit) || substeps < kMinBoundedSubsteps ||
      substeps > kMaxBoundedSubsteps || split < kMinSplitSteps || split > kMaxSplitSteps)
    return false;
  l.contact_scheme = static_cast<ContactScheme>(scheme);
  l.bounded_substeps = substeps;
  l.split_steps = split;
  c->budget_ticks = r.u32();
  c->comp_kind = static_cast<CompKind>(r.u8());
  c->comp_window_s = r.f64();
  const std::uint8_t est = r.u8();
  if (est > static_cast<std::uint8_t>(TwinEstimator::kKalman)) return false;
  c->estimator = static_cast<TwinEstimator>(est);
  return r.done();
}

// The node's own settings, checked (the scene is checked by the model
// builder): the field at fault, or nullptr.
inline const char* validate_node(const NodeConfig& c) {
  auto nonneg = [](double x) { return std::isfinite(x) && x >= 0.0; };
  const double rate = c.scene.loop.sensor_rate_hz;
  if (!(rate > 0.0 && rate <= 1e6)) return "loop.sensor_rate_hz: must be in (0, 1e6]";
  if (!nonneg(c.sensor_range_mps2)) return "sensor_range: must be finite and >= 0";
  if (!(c.grace_periods >= 0.5 && c.grace_periods <= 1000.0)) return "grace: must be 0.5 to 1000 periods";
  if (!(c.stall_periods >= 1.0 && c.stall_periods <= 1e6)) return "stall: must be 1 to 1e6 periods";
  for (int i = 0; i < c.scene.frame.stories; ++i)
    if (!nonneg(c.drift_limit_m[i])) return "drift_limit: must be finite and >= 0";
  if (!nonneg(c.residual_limit_mps2)) return "residual_limit: must be finite and >= 0";
  if (c.estimator != TwinEstimator::kNone && c.mode != NodeMode::kTwin) return "estimator: only in twin mode";
  if (!(c.residual_window_s > 0.0 && std::isfinite(c.residual_window_s))) return "residual_window: must be > 0";
  if (!(c.comp_delay_s >= 0.0 && c.comp_delay_s <= 1.0)) return "comp_delay: must be 0 to 1 s";
  if (c.comp_order < 1 || c.comp_order > 3) return "comp_order: must be 1, 2 or 3";
  if (static_cast<std::uint8_t>(c.comp_kind) >= kCompKinds)
    return "comp_kind: must be 0 (none), 1 (polynomial) or 2 (adaptive)";
  if (!(c.comp_window_s >= 0.05 && c.comp_window_s <= 100.0)) return "comp_window: must be 0.05 to 100 s";
  if (c.comp_kind == CompKind::kAdaptive && c.comp_delay_s > 0.1)
    return "comp_delay: the adaptive compensator's initial a1 must be 0 to 0.1 s";
  return nullptr;
}

}  // namespace vines::link
