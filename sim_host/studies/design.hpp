// `vines design`: the best value of one design parameter of a scene, for one
// record or robustly over several (mean or worst case of x_r or E_r): a coarse
// grid, then golden-section refinement of the bracket around the grid's best.
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace vines::host {

struct DesignOptions {
  std::string scene_path;
  std::string key;                   // scene key, e.g. "vines.beta"
  double lo = 0, hi = 0;             // search range
  int coarse = 21;                   // coarse grid points
  int refine = 12;                   // golden-section iterations
  std::vector<std::string> records;  // empty: the scene's record
  std::string objective = "mean";    // "mean" or "worst" over the records
  std::string metric = "x_r";        // "x_r" or "E_r"
  int threads = 0;
  const std::atomic<bool>* stop = nullptr;  // set (Ctrl-C): the search ends with DesignInterrupted
};

// Shorthands for --optimize: beta, eps, mass_ratio; anything with a dot is a
// scene key. Fills key and the default range; false if unknown.
bool design_parameter(const std::string& name, DesignOptions* opt);

// One value tried: its objective, and in which phase ("grid", "refine"). A
// value with a degraded run (on any record) cannot be the best: the search
// takes it as worse than every other.
struct DesignEvaluation {
  double value = 0, objective = 0;
  std::string phase;
  std::string degraded_reasons;  // codes of its degraded runs ("": ok)
};

// design.json: the search, the best value found and every evaluation.
struct DesignResult {
  DesignOptions options;
  double best_value = 0, best_objective = 0;
  bool found = false;  // false: every value tried was degraded (best_* mean nothing)
  std::vector<DesignEvaluation> evaluations;
  std::size_t degraded() const;
  nlohmann::json to_json() const;
};

// The search was stopped (DesignOptions::stop): it has no result.
class DesignInterrupted : public std::runtime_error {
 public:
  DesignInterrupted() : std::runtime_error("design: interrupted") {}
};

// Runs the search (the runs of each step through the sweep's parallel map).
DesignResult optimize_design(const DesignOptions& opt);

}  // namespace vines::host
