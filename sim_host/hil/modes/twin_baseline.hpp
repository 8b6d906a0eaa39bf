// A twin's commissioning baseline (docs/twin.md section 5): what a
// monitoring team records when it installs the system. The node, run on one
// or more healthy records of the building (`vines hil --mode twin
// --commission FILE`, each run adding to FILE), leaves the stories' losses
// it identified on each; the twin then runs from their mean and spread
// (`--baseline FILE`) instead of the drawing. The file is JSON:
//   {"format": "vines twin baseline", "version": 1, "stories": N,
//    "device": "none|tmd|vines", "sensors": [floors], "sensor_rate_hz": R,
//    "runs": [{"truth": path, "record": path, "loss": [N], "loss_sd": [N]}]}
#pragma once

#include <string>
#include <vector>

#include "sim_host/hil/modes/twin_design.hpp"
#include "sim_host/hil/options.hpp"
#include "sim_host/hil/report.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {

// The building a baseline belongs to: a baseline of another is refused.
struct TwinBuilding {
  int stories = 0;
  std::string device;
  std::vector<int> sensors;
  double sensor_rate_hz = 0;
};

// The building the node's scene and the twin options describe.
TwinBuilding twin_building(const Scene& node, const HilOptions& o);

// The baseline in FILE for this building: the runs' mean loss per story,
// and its covariance: the runs' spread (times 1 + 1/runs: the mean's own
// error too) plus each run's estimate variance (its mean, times the
// tuning's inflation); with one run, no spread (design_twin adds the
// masses' effect in its place). Throws std::runtime_error naming FILE and what is
// wrong (not a baseline, another building, no run, a value not finite).
TwinBaselineStats load_twin_baseline(const std::string& path, const TwinBuilding& b, const TwinTuning& t);

// Throws as commission_twin would if FILE (missing is fine) cannot take
// this building's runs: checked before a commissioning run, not after it.
void check_commission_file(const std::string& path, const TwinBuilding& b);

// Adds the run's final estimates to FILE (created if missing; atomically
// replaced), after checking that FILE is a baseline of this building and
// that the run has no caveat (its estimates outside what a building of this
// drawing can be: not added, std::runtime_error naming FILE and the caveat).
void commission_twin(const std::string& path, const TwinBuilding& b, const HilTwinReport& run,
                     const std::string& record);

}  // namespace vines::host
