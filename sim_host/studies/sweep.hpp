// `vines sweep`: grids of runs that differ from a base scene in a few keys,
// spread over threads (and MPI ranks), with per-study statistics.
//
// A spec file holds one or more [[study]] tables:
//   name     = "clearance"
//   scene    = "../scenes/elcentro_vines.toml"   (relative to the spec)
//   group_by = "vines.beta"     optional: statistics per value of this key
//   optimize = "x_r"            optional: "x_r" or "E_r", report the best value
//                               of group_by (by mean) or of the single grid key
//   [study.set]   "key" = value                   fixed overrides of scene keys
//   [[study.cases]] "key" = value, ...            paired overrides, one case each
//   [study.grid]  "key" = [values] | {from, to, step | count, scale}
//                 or a list of such tables (their union); scale = "gap" (the
//                 VI NES free travel) or "vmax" (the bare frame's peak top
//                 velocity) multiplies the values; a value "unset" removes
//                 the key from the scene; "record.path" also takes
//                 { folder = "DIR", glob = "*.at2" }: every file of DIR
//                 (relative to the spec) matching glob, sorted, each read
//                 with its own format and units (as vines run --record).
// Runs are the product cases x grid; each is the scene with its keys set. A
// run's x_r and E_r compare it with the bare frame on the same record.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace vines::host {

// Plans above this many runs need --large (Python: large=True): the plan
// alone takes gigabytes before any run.
constexpr std::uint64_t kLargePlan = 1000000;
// The most threads a sweep takes (--threads; Python's threads).
constexpr int kMaxThreads = 1024;

struct SweepOptions {
  std::string out_dir;  // "" = out/<spec stem>
  int threads = 0;      // 0 = all cores
  bool progress = true;
};

// One value of a scene key: a number (integral if it came as an integer), a
// string, or "unset".
struct KeyValue {
  std::string key;
  double number = 0;
  bool integral = false;
  std::string text;  // a string value ("unset" removes the key), or "scale:gap"/"scale:vmax"
  // A file of a record folder (record.path only): read as `vines run --record`
  // reads it, its own format, units, column and time step.
  bool record_file = false;
  std::string label() const;   // the value as written in results.csv
  std::string column() const;  // its results.csv column: the key, "/gap" or "/vmax" when scaled
  bool scaled() const { return text.rfind("scale:", 0) == 0; }
};

struct RunPlan {
  int study = 0;
  std::vector<KeyValue> values;  // cases and grid, in column order
};

struct RunResult {
  bool done = false;
  std::string error;  // non-empty: the run was refused or failed
  std::string device;
  double x_r = 0, E_r = 0, peak_top = 0, elastic_energy = 0, residual = 0;
  long long contacts = 0, cap_hits = 0;
  // The run's guards and limits (either run: the device's or its bare
  // frame's), and its status (sim_host/run/status.hpp): degraded runs are kept
  // out of the statistics and counted apart.
  long long bad_samples = 0, divergences = 0;
  double max_overlap = 0;
  bool energy_checked = false;      // residual was computed (loop.energy_ledger)
  bool degraded = false;
  std::string degraded_reasons;     // codes joined with ';' ("" when ok)
};
// A result as JSON (a line of DIR/runs.jsonl, sweep_log.hpp): every member,
// by name; a member missing from the JSON keeps its default.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RunResult, done, error, device, x_r, E_r, peak_top, elastic_energy,
                                                residual, contacts, cap_hits, bad_samples, divergences, max_overlap,
                                                energy_checked, degraded, degraded_reasons)

struct StudySpec {
  std::string name, scene_path, group_by, optimize;
  // The scene as TOML text, when it is not the file scene_path (a scene of
  // the Python package): scene_path then names it and resolves its record.
  std::string scene_toml;
  std::vector<KeyValue> set;
  std::vector<std::vector<KeyValue>> cases;
  std::vector<std::vector<KeyValue>> grid_axes;  // one list of values per key
};

struct SweepSpec {
  std::string path;
  std::vector<StudySpec> studies;
};

// A spec whose grids make more runs than this is refused by load_sweep (from
// the counts, before any value is built): its plan cannot fit in memory.
inline constexpr std::uint64_t kMaxPlanRuns = 1000000000;

SweepSpec load_sweep(const std::string& path);
// The same from the spec's text (path names it and anchors relative scene
// and folder paths); the studies' scenes are not loaded.
SweepSpec parse_sweep(const std::string& text, const std::string& path);

// The number of runs of the spec, from its axes (nothing materialised);
// UINT64_MAX when the product overflows.
std::uint64_t plan_size(const SweepSpec& spec);
// About the memory a plan of n runs of the spec takes with its results
// [bytes], and this machine's memory [bytes]: a plan over half of it is
// refused (vines sweep, vines.sweep).
double plan_memory_bytes(const SweepSpec& spec, std::uint64_t n);
double machine_memory_bytes();

// Run `index` (< plan_size) of the spec.
RunPlan plan_run(const SweepSpec& spec, std::uint64_t index);

// Every run of the spec, in a fixed order (results are indexed by it).
std::vector<RunPlan> plan_runs(const SweepSpec& spec);

class SweepLog;

// Runs plan[i] for every i with i % stride == offset (others stay not done)
// that is not done in `finished` (empty, or one result per run: those of a
// resumed sweep), on `threads` threads (parallel_map). Each finished run is
// appended to *log when given. Once *stop is set no run starts and the runs
// under way are dropped (within a second).
std::vector<RunResult> execute(const SweepSpec& spec, const std::vector<RunPlan>& plan, int threads,
                               int offset, int stride, const std::atomic<bool>* stop,
                               bool progress, SweepLog* log = nullptr, std::vector<RunResult> finished = {});

// Mean, sample standard deviation, range and count of some x_r or E_r.
struct Stats {
  double mean = 0, sd = 0, min = 0, max = 0;
  std::size_t n = 0;
};

// The runs of a study with one value of its group key.
struct GroupSummary {
  double value = 0;      // the key's value, when a number
  std::string text;      // the key's value, when a string (a record file)
  std::optional<Stats> x_r, E_r;  // none when every run of the group is degraded
  std::size_t degraded = 0;
};

struct StudySummary {
  std::string name, scene, device;
  std::size_t runs = 0;                 // finished without error (ok and degraded)
  std::size_t degraded = 0;             // of which degraded: not in the statistics
  std::optional<Stats> x_r, E_r;        // over the ok runs; none when there is none
  bool energy_checked = true;           // every run computed its energy balance
  std::string group_by;                 // the group key ("": no groups)
  std::vector<GroupSummary> groups;     // by value
  std::string optimize;                 // "", "x_r" or "E_r"
  double best_value = 0, best = 0;      // the group of the best mean (with optimize)
  std::string best_text;                // its value when a string
};

// summary.json of a sweep.
struct SweepSummary {
  std::string spec;
  std::size_t runs = 0, done = 0, failed = 0, degraded = 0;
  double wall_s = 0;
  int cores = 1;  // threads used, over every rank
  std::vector<StudySummary> studies;
  double runs_per_s() const { return wall_s > 0 ? done / wall_s : 0.0; }
  double runs_per_s_per_core() const { return runs_per_s() / cores; }
  nlohmann::json to_json() const;
};

// results.csv and summary.json of a (possibly partial) result set in
// out_dir, run in wall_s on `cores` threads (over every rank); returns the summary.
SweepSummary write_sweep(const SweepSpec& spec, const std::vector<RunPlan>& plan,
                         const std::vector<RunResult>& results, const std::string& out_dir, double wall_s,
                         int cores = 1);

}  // namespace vines::host
