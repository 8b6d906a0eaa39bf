// `vines bench`: speed against accuracy. For each scene, scalar and loop
// setting (sensor rate, contact sub-step tolerance) it times full runs of the
// firmware loop (record already loaded, model already built; median of
// repeats) and measures their error against the converged reference
// (data/reference/<scene>.json, written by `vines reference`). Baselines
// (DOP853 with event location in double, SUNDIALS CVODE Adams and BDF, on
// the same model) run in the same process.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/reference/truth.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {

// The truth a line is measured against.
struct Truth {
  bool known = false;
  std::string source;  // the file it came from
  double peak_top = 0, elastic_energy = 0;
  int contacts = 0;
  bool has_x_r = false;
  double x_r = 0, E_r = 0;
  double bare_peak_top = 0, bare_elastic_energy = 0;
};

// One line of the work-precision table.
struct BenchLine {
  std::string scene, method, scalar;  // method: "firmware" or one of kBaselineMethods
  // Firmware lines: the contact scheme ("adaptive", "bounded", "split") and
  // its budget (bounded: sub-steps a step, split: Runge-Kutta steps a
  // contact scale, else 0); the most sub-steps any step took.
  std::string scheme = "adaptive";
  int budget = 0;
  long long max_substeps_in_step = 0;
  double rate_hz = 0, rtol = 0;
  int runs = 0;
  double wall_median_s = 0, wall_min_s = 0, build_s = 0;
  long long steps = 0, substeps = 0, rejected = 0;
  double peak_top = 0, elastic_energy = 0, x_r = 0;
  int contacts = 0;
  // Errors against the truth (NaN when it is not known).
  double peak_rel_error = 0, elastic_energy_rel_error = 0, x_r_abs_error = 0;
};

struct BenchOptions {
  std::vector<std::string> scalars;  // "double", "float", "fixed"; empty: double and float
  std::vector<double> rates_hz;      // empty: the scene's own
  std::vector<double> rtols;         // contact sub-step tolerances; empty: the scene's own
  // Contact schemes ("adaptive": a line per rtol; "bounded": a line per
  // budget in bounded_substeps, "split": per split_steps; empty lists: the
  // scene's own); empty: the scene's.
  std::vector<std::string> schemes;
  std::vector<int> bounded_substeps;
  std::vector<int> split_steps;
  double min_time_s = 0.3;           // time each line for at least this long...
  int min_runs = 3;                  // ...and at least this many runs
  std::string reference_dir;         // "": data/reference of the source tree
  // Off: the loop computes what the table needs (top-floor peak, E_e,
  // contacts), as a study does. On: the scene's own outputs (per-floor
  // peaks, energy ledger) are computed too.
  bool full_outputs = false;
  // Baselines on the same model at these tolerances, fed the record's own
  // points (the same piecewise-linear input); empty: none.
  std::vector<double> baseline_rtols;
  // Which baselines (kBaselineMethods); empty: all four.
  std::vector<std::string> baseline_methods;
  int threads = 0;  // the ensemble's references (0: all cores); the timed runs are one at a time
};

// The baseline methods by name, in table order.
extern const char* const kBaselineMethods[4];

// One firmware setting of the table: scalar, sensor rate, contact tolerance,
// contact scheme and its budget (bounded: sub-steps a step, split:
// Runge-Kutta steps a contact scale, adaptive: 0).
struct FirmwareSetting {
  Scalar scalar = Scalar::kDouble;
  double rate_hz = 0, rtol = 0;
  ContactScheme scheme = ContactScheme::kAdaptive;
  int budget = 0;
};
// One baseline setting: method (kBaselineMethods) and tolerance.
struct BaselineSetting {
  std::string method;
  double rtol = 0;
};

// The settings the options ask for on a scene, in table order (throws
// std::runtime_error naming the option at fault).
std::vector<FirmwareSetting> firmware_settings(const Scene& scene, const BenchOptions& opt);
std::vector<BaselineSetting> baseline_settings(const BenchOptions& opt);
// The scene at a setting (only the outputs the table needs, unless
// opt.full_outputs).
Scene with_setting(const Scene& base, const FirmwareSetting& set, const BenchOptions& opt);
const char* scheme_name(ContactScheme s);
// The baseline method of a name of kBaselineMethods (throws naming --baseline-methods).
reference::Method baseline_method(const std::string& name);

// The scene's reference, or an unknown truth if there is none on file.
Truth load_truth(const Scene& scene, const std::string& reference_dir);

// All lines for one scene.
std::vector<BenchLine> bench_scene(const Scene& scene, const BenchOptions& opt);

nlohmann::json line_json(const BenchLine& l);

// The table, one line per row, with a header.
std::string format_table(const std::vector<BenchLine>& lines);

}  // namespace vines::host
