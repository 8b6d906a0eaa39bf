// `vines sweep`'s outputs: each study's statistics, results.csv and
// summary.json, from the runs' results (sweep.cpp runs them).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "sim_host/io/csv.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/studies/sweep.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- statistics ----

std::optional<Stats> stats(const std::vector<double>& v) {
  if (v.empty()) return std::nullopt;
  double mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  const double sd = v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : 0.0;
  return Stats{mean, sd, *std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end()), v.size()};
}

json stats_json(const std::optional<Stats>& s) {
  if (!s) return nullptr;
  return {{"mean", s->mean}, {"sd", s->sd}, {"min", s->min}, {"max", s->max}, {"n", s->n}};
}

// A study's statistics: over its finished runs that are ok (degraded ones
// counted apart), and per value of group_by (or of its single grid key when
// it optimises).
StudySummary summarize_study(const SweepSpec& spec, int s, const std::vector<RunPlan>& plan,
                             const std::vector<RunResult>& results) {
  const StudySpec& st = spec.studies[s];
  StudySummary out;
  out.name = st.name;
  out.scene = st.scene_path;
  out.optimize = st.optimize;
  struct Figures {
    std::vector<double> xr, er;
    std::size_t degraded = 0;
    void add(const RunResult& r) {
      if (r.degraded) return void(++degraded);
      xr.push_back(r.x_r);
      er.push_back(r.E_r);
    }
  };
  Figures all;
  // By value: numbers in order, strings (record files) by name.
  std::map<std::pair<double, std::string>, Figures> groups;
  const std::string gkey = !st.group_by.empty() ? st.group_by
                           : (!st.optimize.empty() && st.grid_axes.size() == 1) ? st.grid_axes[0].front().key
                                                                                  : "";
  for (std::size_t i = 0; i < plan.size(); ++i) {
    if (plan[i].study != s || !results[i].done || !results[i].error.empty()) continue;
    all.add(results[i]);
    out.device = results[i].device;
    out.energy_checked &= results[i].energy_checked;
    for (const KeyValue& v : plan[i].values)
      if (v.key == gkey) groups[{v.text.empty() ? v.number : 0.0, v.text}].add(results[i]);
  }
  out.runs = all.xr.size() + all.degraded;
  out.degraded = all.degraded;
  out.x_r = stats(all.xr);
  out.E_r = stats(all.er);
  if (groups.empty()) return out;
  out.group_by = gkey;
  out.best = -1e300;
  // The best group: of the best mean over its ok runs.
  for (auto& [value, g] : groups) {
    out.groups.push_back({value.first, value.second, stats(g.xr), stats(g.er), g.degraded});
    const std::optional<Stats>& m = st.optimize == "E_r" ? out.groups.back().E_r : out.groups.back().x_r;
    if (m && m->mean > out.best) {
      out.best = m->mean;
      out.best_value = value.first;
      out.best_text = value.second;
    }
  }
  return out;
}

// ---- results.csv ----
void write_results_csv(const SweepSpec& spec, const std::vector<RunPlan>& plan, const std::vector<RunResult>& results,
                       const fs::path& file) {
  // Columns: every key any study varies, in order of first appearance.
  std::vector<std::string> keys;
  for (const RunPlan& r : plan)
    for (const KeyValue& v : r.values)
      if (std::find(keys.begin(), keys.end(), v.column()) == keys.end()) keys.push_back(v.column());
  CsvWriter csv(file.string());
  csv.raw("study").raw("run").raw("device");
  for (const std::string& k : keys) csv.text(k);
  for (const char* h : {"x_r", "E_r", "peak_top_displacement_m", "elastic_energy_integral", "contacts",
                        "energy_balance_residual", "substep_cap_hits", "bad_samples_held", "divergences_rolled_back",
                        "max_overlap_m", "status", "degraded_reasons", "error"})
    csv.raw(h);
  csv.end_row();
  // One row per finished run; a failed one has its message in the last column.
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const RunResult& r = results[i];
    if (!r.done) continue;
    csv.text(spec.studies[plan[i].study].name).integer(static_cast<long long>(i)).text(r.device);
    for (const std::string& k : keys) {
      std::string cell;
      for (const KeyValue& v : plan[i].values)
        if (v.column() == k) cell += v.label();
      csv.text(cell);
    }
    // A residual not computed (loop.energy_ledger = false) is an empty cell.
    if (r.error.empty()) {
      csv.number(r.x_r, "%.10g").number(r.E_r, "%.10g").number(r.peak_top, "%.10g");
      csv.number(r.elastic_energy, "%.10g").integer(r.contacts);
      if (r.energy_checked) csv.number(r.residual, "%.3g");
      else csv.empty();
      csv.integer(r.cap_hits).integer(r.bad_samples).integer(r.divergences).number(r.max_overlap, "%.6g");
      csv.raw(r.degraded ? "degraded" : "ok").text(r.degraded_reasons).empty();
    } else {
      for (int c = 0; c < 12; ++c) csv.empty();
      csv.quoted(r.error);
    }
    csv.end_row();
  }
  csv.close();
}

}  // namespace

json SweepSummary::to_json() const {
  json js = json::array();
  for (const StudySummary& st : studies) {
    json j = {{"name", st.name}, {"scene", st.scene}, {"device", st.device}, {"runs", st.runs},
              {"x_r", stats_json(st.x_r)}, {"E_r", stats_json(st.E_r)}, {"degraded", st.degraded}};
    if (!st.energy_checked) j["energy_balance"] = "not computed in every run (loop.energy_ledger = false)";
    if (!st.groups.empty()) {
      json jg = json::array();
      for (const GroupSummary& g : st.groups)
        jg.push_back({{"value", g.text.empty() ? json(g.value) : json(g.text)}, {"x_r", stats_json(g.x_r)},
                      {"E_r", stats_json(g.E_r)}, {"degraded", g.degraded}});
      j["group_by"] = st.group_by;
      j["groups"] = jg;
      if (!st.optimize.empty())
        j["best"] = {{"key", st.group_by},
                     {"value", st.best_text.empty() ? json(st.best_value) : json(st.best_text)},
                     {st.optimize, st.best}};
    }
    js.push_back(j);
  }
  return {{"spec", spec},   {"runs", runs},           {"done", done},
          {"failed", failed}, {"complete", done == runs}, {"wall_time_s", wall_s},
          {"runs_per_s", runs_per_s()}, {"cores", cores}, {"runs_per_s_per_core", runs_per_s_per_core()},
          {"studies", js}, {"degraded", degraded}};
}

SweepSummary write_sweep(const SweepSpec& spec, const std::vector<RunPlan>& plan,
                         const std::vector<RunResult>& results, const std::string& out_dir, double wall_s,
                         int cores) {
  create_folder(out_dir);
  write_results_csv(spec, plan, results, fs::path(out_dir) / "results.csv");
  SweepSummary s;
  s.spec = spec.path;
  s.runs = plan.size();
  s.wall_s = wall_s;
  s.cores = cores;
  for (const RunResult& r : results) {
    s.done += r.done;
    s.failed += r.done && !r.error.empty();
    s.degraded += r.done && r.error.empty() && r.degraded;
  }
  for (int i = 0; i < static_cast<int>(spec.studies.size()); ++i)
    s.studies.push_back(summarize_study(spec, i, plan, results));
  write_file_atomic((fs::path(out_dir) / "summary.json").string(), s.to_json().dump(2) + '\n');
  return s;
}

}  // namespace vines::host
