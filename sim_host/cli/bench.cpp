// `vines bench SCENE.toml...`: speed against accuracy, against data/reference.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/bench/bench.hpp"
#include "sim_host/bench/ensemble.hpp"
#include "sim_host/cli/cli.hpp"
#include "sim_host/io/csv.hpp"
#include "sim_host/reference/truth.hpp"
#include "sim_host/scene/scene.hpp"
#include "vines/model/params.hpp"

namespace vines::cli {
namespace {

struct BenchArgs {
  std::vector<std::string> scenes;
  host::BenchOptions opt;
  bool as_json = false, no_baselines = false;
  int ensemble = 0;  // members; 0: the scene alone
  std::string csv;
  const CLI::Option* baselines = nullptr;  // --baselines, given or not
};

// The lines as CSV: a header of the JSON keys, then one row per line, each
// value as JSON writes it (strings quoted, null for unknown errors).
void write_csv(const std::string& path, const std::vector<host::BenchLine>& lines) {
  host::CsvWriter csv(path);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const nlohmann::json j = host::line_json(lines[i]);
    if (i == 0) {
      for (auto it = j.begin(); it != j.end(); ++it) csv.text(it.key());
      csv.end_row();
    }
    for (auto it = j.begin(); it != j.end(); ++it) csv.raw(it.value().dump());
    csv.end_row();
  }
  csv.close();
}

int bench(BenchArgs a) {
  using namespace vines::host;
  BenchOptions& opt = a.opt;
  // The table has baselines by default; --json alone is the scene's own line.
  if (a.baselines->count() == 0 && !a.as_json) opt.baseline_rtols = {1e-6, 1e-8, 1e-10};
  if (a.no_baselines) opt.baseline_rtols.clear();
  // Refused before any run: a table without the lines it was asked for is a silent wrong result.
  const std::vector<std::string>& methods = opt.baseline_methods;
  const bool cvode = methods.empty() || std::any_of(methods.begin(), methods.end(), [](const std::string& m) {
                       return m.rfind("cvode", 0) == 0;
                     });
  if (!opt.baseline_rtols.empty() && cvode && *reference::cvode_missing())
    throw std::runtime_error(std::string("the CVODE baselines (") +
                             (methods.empty() ? "--baseline-methods default: all four" : "--baseline-methods") +
                             "): " + reference::cvode_missing() +
                             "; or leave them out with --baseline-methods dop853 or --no-baselines");
  std::vector<Scene> scenes;
  for (const std::string& path : a.scenes) {
    scenes.push_back(load_scene(path));
    if (a.ensemble > 0 && scenes.back().params.device.kind != DeviceKind::kVines)
      throw std::runtime_error("--ensemble: " + path + " has no VI NES (the ensemble varies the sphere and the record)");
  }
  std::vector<BenchLine> lines;
  std::vector<EnsembleLine> ensemble;
  for (const Scene& scene : scenes) {
    BenchOptions o = opt;
    if (o.scalars.empty()) o.scalars = {scalar_name(scene.scalar)};
    const std::vector<BenchLine> ls = bench_scene(scene, o);
    lines.insert(lines.end(), ls.begin(), ls.end());
    if (!a.as_json) std::fputs(format_table(ls).c_str(), stdout);
    if (a.ensemble == 0) continue;
    // The same settings over the ensemble, each member against its own reference.
    const std::vector<EnsembleLine> es = bench_ensemble(scene, o, a.ensemble);
    ensemble.insert(ensemble.end(), es.begin(), es.end());
    if (!a.as_json)
      std::printf("%s over an ensemble of %d (errors: |.| against each member's reference; run_ms: one run):\n%s",
                  scene.name.c_str(), a.ensemble, format_ensemble_table(es).c_str());
  }
  if (!a.csv.empty()) write_csv(a.csv, lines);
  if (a.as_json) {
    nlohmann::json j;
    if (lines.size() == 1 && a.ensemble == 0) {
      j = line_json(lines[0]);
    } else {
      j["lines"] = nlohmann::json::array();
      for (const BenchLine& l : lines) j["lines"].push_back(line_json(l));
    }
    if (a.ensemble > 0) {
      j["ensemble"] = nlohmann::json::array();
      for (const EnsembleLine& l : ensemble) j["ensemble"].push_back(ensemble_line_json(l));
    }
    std::printf("%s\n", j.dump(2).c_str());
  }
  return kOk;
}

}  // namespace

void add_bench(CLI::App& vines) {
  auto a = std::make_shared<BenchArgs>();
  host::BenchOptions& opt = a->opt;
  CLI::App* cmd = add_command(
      vines, "bench",
      "Speed against accuracy: wall time of full runs (record loaded, model built; median of repeats) and their "
      "error against the converged reference (DIR/<scene name>.json, default data/reference, written by `vines "
      "reference`), per sensor rate, tolerance (or bounded sub-step budget), contact scheme and scalar.",
      "", [a] { return bench(*a); });
  cmd->add_option("SCENE.toml", a->scenes, "scene files (see data/scenes/README.md)")->required();
  add_number_list(*cmd, "--rates", &opt.rates_hz, "sensor rates [Hz] (default: the scene's)");
  add_number_list(*cmd, "--rtols", &opt.rtols, "contact sub-step tolerances (default: the scene's)");
  cmd->add_option("--scalars", opt.scalars, "double,float,fixed (default: double and float; fixed needs the split scheme)")
      ->type_name("LIST")
      ->delimiter(',')
      ->check(CLI::IsMember({"double", "float", "fixed"}));
  cmd->add_option("--schemes", opt.schemes,
                  "contact schemes: adaptive (a line per --rtols), bounded (a line per --substeps), split (a line "
                  "per --split-steps) (default: the scene's loop.contact_scheme)")
      ->type_name("LIST")
      ->delimiter(',')
      ->check(CLI::IsMember({"adaptive", "bounded", "split"}));
  add_number_list(*cmd, "--substeps", &opt.bounded_substeps, kMinBoundedSubsteps, kMaxBoundedSubsteps,
                  "bounded scheme: sub-step budgets per sensor step, integers in [2, 64] (default: the scene's "
                  "loop.bounded_substeps)");
  add_number_list(*cmd, "--split-steps", &opt.split_steps, kMinSplitSteps, kMaxSplitSteps,
                  "split scheme: Runge-Kutta steps per unit of a contact's scale, integers in [4, 1024] (default: "
                  "the scene's loop.split_steps)");
  a->baselines = add_number_list(*cmd, "--baselines", &opt.baseline_rtols,
                                 "baseline lines (see --baseline-methods) at these tolerances, fed the record's own "
                                 "points (default 1e-6,1e-8,1e-10; none with --json)");
  cmd->add_option("--baseline-methods", opt.baseline_methods,
                  "baselines: dop853 (DOP853 in double, events on its dense output), dop853-driver (the "
                  "reference's driver in double, events by re-taking the step), cvode-adams, cvode-bdf (SUNDIALS "
                  "CVODE) (default: all four)")
      ->type_name("LIST")
      ->delimiter(',')
      ->check(CLI::IsMember({"dop853", "dop853-driver", "cvode-adams", "cvode-bdf"}));
  cmd->add_flag("--no-baselines", a->no_baselines, "no baseline lines");
  cmd->add_option("--ensemble", a->ensemble,
                  "also run every line over N members (VI NES scenes: the AT2 records beside the scene's record at "
                  "its PGA, and initial conditions of the 33 x 33 grid), each against its own converged reference: "
                  "mean and p90 of the errors, contact agreement, cost of a run")
      ->type_name("N")
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--threads", opt.threads, "threads for the ensemble's references (default: all cores)")
      ->type_name("N")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--min-time", opt.min_time_s, "time each line for at least S seconds (default 0.3)")
      ->type_name("S")
      ->check(positive_up_to(std::numeric_limits<double>::max()));
  cmd->add_option("--reference", opt.reference_dir, "the references' folder (default: data/reference)")
      ->type_name("DIR");
  cmd->add_flag("--full-outputs", opt.full_outputs,
                "also compute the scene's per-floor peaks and energy ledger (default: only what the table needs, "
                "as a study run does)");
  cmd->add_flag("--json", a->as_json, "print JSON: one object for a single line, else {\"lines\": [...]}");
  cmd->add_option("--csv", a->csv, "also write the lines as CSV")->type_name("FILE")->check(non_empty_path());
}

}  // namespace vines::cli
