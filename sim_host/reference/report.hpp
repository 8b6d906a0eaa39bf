// `vines reference`: a scene and its bare frame integrated by the reference
// at two tolerances (its own convergence check), as a typed report whose
// to_json() is the file data/reference/<scene>.json.
#pragma once

#include <cmath>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "sim_host/reference/truth.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host::reference {

// The same scene on the record's own knots (when the sensor grid holds them):
// the steps the controller chooses up to dt instead of the sensor period.
struct KnotRun {
  double sample_rate_hz = 0;
  Result result;
};

struct ReferenceReport {
  std::string scene, scene_file;
  RecordSummary record;      // its path as the scene names it
  double sample_rate_hz = 0; // the record's sensor rate
  double rtol = 0, rtol_coarse = 0;
  Result run, coarse;        // the scene at rtol and at rtol_coarse
  Result bare, bare_coarse;  // its bare frame (the scene's own runs without a device)
  std::optional<KnotRun> knots;
  double x_r() const { return reduction(bare.peak_top, run.peak_top); }
  double E_r() const { return reduction(bare.elastic_energy, run.elastic_energy); }
  nlohmann::json to_json() const;
};

// |a - b| relative to |b| (absolute when b is 0): how far a coarse run is
// from the fine one.
inline double rel_diff(double a, double b) { return b != 0.0 ? std::fabs(a - b) / std::fabs(b) : std::fabs(a - b); }

// rtol 0: the reference default. The coarse run uses 100 * rtol. Throws
// std::runtime_error naming the input on any problem.
ReferenceReport reference_report(const Scene& scene, double rtol);

}  // namespace vines::host::reference
