// Whether a run's results can be trusted: `ok`, or `degraded` with the
// reasons (the guards and limits of the loop that it ran into, counted by the
// firmware). Every result of `vines run`, `vines sweep`, `vines design` and
// `vines stress` carries one (rules and bounds: docs/model.md, "Run status").
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/engines/engine.hpp"
#include "sim_host/scene/scalar.hpp"

namespace vines::host {

// Energy balance residual (Ledger::relative_residual) above which a run is
// degraded, by scalar: the shipped scenes give 2e-13..7e-11 (adaptive) and
// 1.6e-6 (bounded scheme), the stress test's random cases stay below 1e-5
// (Hertz) in double and 5e-3 in float.
inline constexpr double kResidualBoundDouble = 1e-4;
inline constexpr double kResidualBoundFloat = 1e-2;
// Deepest VI NES overlap, as a fraction of the particle radius, past which
// Hertz' small-strain contact (contact radius sqrt(R d) small against R) no
// longer holds: d = R/100 is a contact radius of R/10.
inline constexpr double kOverlapLimitOfRadius = 0.01;

// One reason: a short code (results.csv, summary.json) and a sentence with
// the figure and the setting behind it.
struct StatusReason {
  std::string code, message;
};

struct RunStatus {
  std::vector<StatusReason> reasons;  // empty: ok
  bool energy_checked = false;        // the ledger was on (its residual was checked)
  bool ok() const { return reasons.empty(); }
  const char* name() const { return ok() ? "ok" : "degraded"; }
  // The codes joined with ';' (a results.csv cell), "" when ok.
  std::string codes() const;
  // [{"code", "message"}, ...] (summary.json's degraded_reasons).
  nlohmann::json reasons_json() const;
  // Adds the reasons of a companion run (the bare frame): codes prefixed
  // "bare_", messages "bare frame: ...".
  void add_companion(const RunStatus& bare);
};

// The status of one engine run from its totals, the parameters it ran with
// (device kind, loop settings) and its model (the VI NES radius).
RunStatus run_status(const RunTotals& t, const SceneParams& p, const ModelInfo& info, Scalar scalar);

// A device run and its bare frame (when there is one): degraded if either is,
// or if x_r / E_r against the bare frame are not finite.
RunStatus device_status(const RunTotals& t, const RunTotals* bare, const SceneParams& p, const ModelInfo& info,
                        Scalar scalar);

}  // namespace vines::host
