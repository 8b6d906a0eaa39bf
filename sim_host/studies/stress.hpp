// `vines stress`: thousands of random scenes over the whole parameter space
// (frames of 1-40 stories, every contact law and the bare frame, records from
// the ground-motion folder scaled 0.05-20x, sensor rates 50 Hz-20 kHz), each
// run and checked: finite outputs, energy balance, overlaps, sub-step cap,
// loop guards, convergence when the step is halved. A case is drawn from
// (seed, index) alone, so results do not depend on the thread count and any
// case can be drawn again.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "host/record.hpp"
#include "sim_host/scene/scalar.hpp"
#include "vines/model/params.hpp"

namespace vines::host {

// ---- drawing scenes (stress_scene.cpp) ----

// A record of the ground-motion folder and how to read it.
struct StressRecord {
  std::string file;
  hal::RecordSpec spec;  // path resolved
  hal::Record record;    // loaded, m/s^2
};

// Every record of the ground-motion folder ($VINES_GROUND_MOTIONS or
// ../shared/data/ground_motions), loaded. Throws if one is missing.
std::vector<StressRecord> load_stress_records();

// One drawn scene: everything needed to run it again.
struct StressCase {
  std::uint64_t seed = 0;
  std::int64_t index = 0;
  SceneParams params;
  Scalar scalar = Scalar::kDouble;
  int record = 0;           // into the record list
  double pga_scale = 1.0;   // multiplies the record
  int first_sample = 0;     // window of the record: first sample...
  int window_samples = 0;   // ...and how many
  int small_cap = 0;        // > 0: also run with max_substeps_per_step = small_cap
};

// Limits of the draw. Steps per run are capped: the window is shortened at
// high sensor rates so that a run takes at most max_steps steps.
struct StressLimits {
  int max_steps = 20000;
  double min_window_s = 2.0, max_window_s = 6.0;
};

StressCase draw_case(std::uint64_t seed, std::int64_t index, const std::vector<StressRecord>& records,
                     const StressLimits& limits);

// The window's ground acceleration [m/s^2], sampled at the case's sensor rate.
std::vector<double> case_samples(const StressCase& c, const std::vector<StressRecord>& records);

// The case as a scene file DIR/case_<index>.toml (with its record window as
// DIR/case_<index>_record.txt), runnable with `vines run`; returns the path.
std::string write_case_scene(const StressCase& c, const std::vector<StressRecord>& records,
                             const std::string& dir);

// The case's parameters, for tables and JSON.
nlohmann::json case_json(const StressCase& c, const std::vector<StressRecord>& records);

// ---- running and checking (stress.cpp) ----

enum StressCheck {
  kFinite,       // every output finite
  kEnergy,       // energy balance residual within its bound
  kOverlap,      // overlap no larger than physically possible
  kGuards,       // no divergence rolled back, no sample held
  kCap,          // no step hit the default sub-step cap
  kSmallCap,     // with a tiny cap, every capped step is reported
  kConvergence,  // same answer when the step is halved
  kCheckCount
};
const char* check_name(int check);

struct CheckResult {
  bool applies = false;
  double value = 0, bound = 0;  // passes when value <= bound
  bool ok() const { return !applies || value <= bound; }
  double ratio() const { return bound > 0 ? value / bound : value; }
};

struct StressResult {
  bool done = false;    // false: not run (interrupted)
  std::string refusal;  // non-empty: refused at scene load ("key: reason")
  std::array<CheckResult, kCheckCount> checks{};
  std::int64_t steps = 0, contacts = 0, cap_hits = 0;
  double wall_s = 0;
  std::string degraded_reasons;  // its run's status (sim_host/run/status.hpp): codes, "" when ok
  nlohmann::json detail;  // the numbers behind the checks
  bool ok() const;
};

StressResult run_case(const StressCase& c, const std::vector<StressRecord>& records);

struct StressOptions {
  std::uint64_t seed = 1;
  std::int64_t count = 2000;
  int threads = 0;  // 0: all cores
  StressLimits limits;
  bool progress = true;
};

struct StressRun {
  std::vector<StressCase> cases;
  std::vector<StressResult> results;
  double wall_s = 0;
};

// Draws and runs cases 0 .. count-1 on `threads` threads.
StressRun run_stress(const StressOptions& opt, const std::vector<StressRecord>& records,
                     const std::atomic<bool>* stop);

// A case listed among the worst of a check.
struct WorstCase {
  std::size_t index = 0;  // into the run's cases
  double value = 0, bound = 0;
  bool ok = true;
  std::string scene_file;  // written as a scene (--out), else ""
};

// One check over the run: how many cases it applied to, failed, the worst.
struct CheckSummary {
  std::size_t runs = 0, failed = 0;
  std::vector<WorstCase> worst;  // worst first, cases at zero left out
};

// Cases refused at scene load for one reason.
struct RefusalSummary {
  std::string reason;
  std::size_t cases = 0;
  std::int64_t first_case = 0;
};

struct StressSummary {
  std::uint64_t seed = 0;
  std::int64_t requested = 0;
  std::size_t cases = 0, refused = 0, failed = 0;  // cases: run (all unless interrupted)
  std::size_t degraded = 0;  // cases whose run status is degraded (as `vines run` would report it)
  bool passed = false;
  std::int64_t steps = 0;
  int max_steps_per_run = 0;
  double wall_s = 0;
  std::vector<RefusalSummary> refusals;  // by reason
  std::array<CheckSummary, kCheckCount> checks;
  double cases_per_s() const { return wall_s > 0 ? cases / wall_s : 0.0; }
  // stress.json; the worst cases' scenes from the run.
  nlohmann::json to_json(const StressRun& run, const std::vector<StressRecord>& records) const;
};

// Summary: per check how many ran and failed and the `worst` worst cases;
// refusals by reason; totals.
StressSummary stress_summary(const StressOptions& opt, const StressRun& run, int worst);

// One case in full: its scene and every check.
nlohmann::json case_report(const StressCase& c, const StressResult& r,
                           const std::vector<StressRecord>& records);

}  // namespace vines::host
