#include "sim_host/run/status.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "sim_host/run/run.hpp"

namespace vines::host {
namespace {

// printf into a std::string (the messages are short).
template <typename... A>
std::string format(const char* fmt, A... a) {
  char buf[320];
  std::snprintf(buf, sizeof buf, fmt, a...);
  return buf;
}

// The names of the figures among `figures` that are not finite, or "".
std::string non_finite(std::initializer_list<std::pair<const char*, double>> figures) {
  std::string out;
  for (const auto& [name, v] : figures)
    if (!std::isfinite(v)) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

}  // namespace

std::string RunStatus::codes() const {
  std::string out;
  for (const StatusReason& r : reasons) out += (out.empty() ? "" : ";") + r.code;
  return out;
}

nlohmann::json RunStatus::reasons_json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const StatusReason& r : reasons) out.push_back({{"code", r.code}, {"message", r.message}});
  return out;
}

void RunStatus::add_companion(const RunStatus& bare) {
  for (const StatusReason& r : bare.reasons) reasons.push_back({"bare_" + r.code, "bare frame: " + r.message});
}

RunStatus run_status(const RunTotals& t, const SceneParams& p, const ModelInfo& info, Scalar scalar) {
  RunStatus s;
  const LoopParams& loop = p.loop;
  const Counters& k = t.count;
  const bool vines = p.device.kind == DeviceKind::kVines;
  auto add = [&s](const char* code, std::string message) { s.reasons.push_back({code, std::move(message)}); };
  // Outputs that are not numbers.
  const std::string bad = non_finite({{"peak top displacement", t.peak_top},
                                      {"E_e", t.elastic_energy},
                                      {"max overlap", vines ? t.max_overlap : 0.0},
                                      {"energy residual", loop.energy_ledger ? t.ledger.relative_residual() : 0.0}});
  if (!bad.empty()) add("non_finite_results", "not finite: " + bad);
  // The loop's guards: samples held, steps rolled back.
  if (k.bad_samples > 0)
    add("bad_samples_held", format("%lld non-finite ground samples held (replaced by the last good one)",
                                   static_cast<long long>(k.bad_samples)));
  if (k.divergences > 0)
    add("divergences_rolled_back", format("%lld steps rolled back (loop.divergence_limit_m = %g)",
                                          static_cast<long long>(k.divergences), loop.divergence_limit_m));
  // The contact schemes' limits: the adaptive cap, the bounded budget, the split cap.
  if (k.cap_hits > 0 && loop.contact_scheme == ContactScheme::kAdaptive)
    add("substep_cap_hits", format("%lld steps hit the sub-step cap (loop.max_substeps_per_step = %d): contacts "
                                   "in them are not resolved",
                                   static_cast<long long>(k.cap_hits), loop.max_substeps_per_step));
  if (k.cap_hits > 0 && loop.contact_scheme == ContactScheme::kBounded)
    add("events_deferred", format("in %lld steps the sub-step budget (loop.bounded_substeps = %d) could not follow "
                                  "every event: they were deferred to the next step or stepped over",
                                  static_cast<long long>(k.cap_hits), loop.bounded_substeps));
  if (k.cap_hits > 0 && loop.contact_scheme == ContactScheme::kSplit)
    add("contact_steps_capped", format("in %lld steps a contact took all %d Runge-Kutta steps the step allows (%d "
                                       "loop.split_steps) before the step's end: the rest of its force was left "
                                       "to the next step",
                                       static_cast<long long>(k.cap_hits), kSplitCap * loop.split_steps, kSplitCap));
  // Fixed point: a value past its format's range was clamped to it.
  if (t.fixed_saturations > 0)
    add("fixed_saturations", format("%lld fixed-point operations saturated: a value passed its unit's range (raise "
                                    "loop.fixed_accel_mps2 or loop.fixed_amplification, docs/fixed_point.md)",
                                    static_cast<long long>(t.fixed_saturations)));
  // The energy balance, when the ledger kept it.
  s.energy_checked = loop.energy_ledger;
  const double bound = scalar == Scalar::kFloat ? kResidualBoundFloat : kResidualBoundDouble;
  const double residual = t.ledger.relative_residual();
  if (loop.energy_ledger && residual > bound)
    add("energy_residual", format("energy balance residual %.2e above its bound %.0e", residual, bound));
  // The contact law's range: the overlap against the particle radius.
  const double radius = info.vines.radius;
  if (vines && t.max_overlap > kOverlapLimitOfRadius * radius)
    add("overlap_beyond_limit", format("deepest overlap %.3g m is %.3g %% of the particle radius %.3g m (limit "
                                       "%g %%: Hertz' small-strain contact)",
                                       t.max_overlap, 100 * t.max_overlap / radius, radius,
                                       100 * kOverlapLimitOfRadius));
  return s;
}

RunStatus device_status(const RunTotals& t, const RunTotals* bare, const SceneParams& p, const ModelInfo& info,
                        Scalar scalar) {
  RunStatus s = run_status(t, p, info, scalar);
  if (bare == nullptr) return s;
  SceneParams pb = p;
  pb.device.kind = DeviceKind::kNone;
  s.add_companion(run_status(*bare, pb, info, scalar));
  // The reductions against the bare frame (a bare peak of zero gives none).
  const std::string bad = non_finite({{"x_r", reduction(bare->peak_top, t.peak_top)},
                                      {"E_r", reduction(bare->elastic_energy, t.elastic_energy)}});
  if (!bad.empty()) s.reasons.push_back({"non_finite_reduction", "not finite: " + bad + " against the bare frame"});
  return s;
}

}  // namespace vines::host
