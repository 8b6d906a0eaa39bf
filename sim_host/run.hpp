// `vines run`: one scene on one record, with the bare frame alongside when the
// scene has a device; writes DIR/summary.json and DIR/timeseries.csv.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/engine.hpp"
#include "sim_host/scene.hpp"

namespace vines::host {

struct RunOptions {
  std::string record_override;  // --record PATH
  std::string out_dir;          // --out DIR ("" = write nothing)
  bool quiet = false;
};

// The record of a scene, loaded, scaled and resampled to the sensor rate.
struct Excitation {
  hal::Record record;
  std::vector<double> samples;  // at the sensor rate, sample k at t = k / rate
  double rate_hz = 0;
};

Excitation load_excitation(const Scene& scene, const std::string& record_override);

// Runs the scene's device (and the bare frame if there is a device), returns
// the summary (also written to out_dir when given). Throws std::runtime_error
// with a message naming the input on any user error.
nlohmann::json run_scene(const Scene& scene, const RunOptions& opt);

}  // namespace vines::host
