#include "sim_host/studies/design.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "sim_host/studies/sweep.hpp"

namespace vines::host {
namespace {

using nlohmann::json;

// A value's objective as the search compares it: a degraded one below all.
double score(const DesignEvaluation& e) { return e.degraded_reasons.empty() ? e.objective : -INFINITY; }

// Each value evaluated: the metric over the records, averaged or worst, and
// the codes of its degraded runs.
std::vector<DesignEvaluation> evaluate(const DesignOptions& opt, const std::vector<double>& values,
                                       const char* phase) {
  SweepSpec spec;
  spec.path = opt.scene_path;
  StudySpec st;
  st.name = "design";
  st.scene_path = opt.scene_path;
  for (const std::string& r : opt.records) {
    KeyValue path{"record.path", 0, false, r}, format{"record.format", 0, false, "auto"};
    st.cases.push_back({path, format});
  }
  std::vector<KeyValue> axis;
  for (double v : values) axis.push_back(KeyValue{opt.key, v, false, ""});
  st.grid_axes.push_back(axis);
  spec.studies.push_back(st);
  const std::vector<RunPlan> plan = plan_runs(spec);
  const std::vector<RunResult> res = execute(spec, plan, opt.threads, 0, 1, opt.stop, false);
  if (opt.stop != nullptr && opt.stop->load()) throw DesignInterrupted();
  std::vector<DesignEvaluation> out;
  for (double v : values) out.push_back({v, 0.0, phase, ""});
  std::vector<int> count(values.size(), 0);
  for (std::size_t i = 0; i < plan.size(); ++i) {
    if (!res[i].error.empty()) throw std::runtime_error(res[i].error);
    const std::size_t j = i % values.size();  // cases outer, grid inner
    DesignEvaluation& e = out[j];
    const double m = opt.metric == "E_r" ? res[i].E_r : res[i].x_r;
    e.objective = opt.objective == "worst" ? (count[j] ? std::min(e.objective, m) : m) : e.objective + m;
    ++count[j];
    if (res[i].degraded) e.degraded_reasons += (e.degraded_reasons.empty() ? "" : ";") + res[i].degraded_reasons;
  }
  if (opt.objective != "worst")
    for (std::size_t j = 0; j < out.size(); ++j) out[j].objective /= count[j];
  return out;
}

}  // namespace

bool design_parameter(const std::string& name, DesignOptions* opt) {
  static const std::map<std::string, std::pair<std::string, std::pair<double, double>>> kKnown = {
      {"beta", {"vines.beta", {1.05, 2.0}}},
      {"eps", {"vines.eps", {0.1, 1.0}}},
      {"mass_ratio", {"device.mass_ratio", {0.01, 0.2}}}};
  const auto it = kKnown.find(name);
  if (it != kKnown.end()) {
    opt->key = it->second.first;
    if (opt->lo == opt->hi) std::tie(opt->lo, opt->hi) = it->second.second;
    return true;
  }
  if (name.find('.') == std::string::npos) return false;
  opt->key = name;
  return opt->lo < opt->hi;  // a raw key needs --range
}

DesignResult optimize_design(const DesignOptions& opt) {
  DesignResult out;
  out.options = opt;
  auto record = [&](const std::vector<DesignEvaluation>& es) {
    out.evaluations.insert(out.evaluations.end(), es.begin(), es.end());
    return es;
  };
  // Coarse grid.
  std::vector<double> grid;
  for (int i = 0; i < opt.coarse; ++i) grid.push_back(opt.lo + (opt.hi - opt.lo) * i / (opt.coarse - 1));
  const std::vector<DesignEvaluation> fg = record(evaluate(opt, grid, "grid"));
  const std::size_t b = static_cast<std::size_t>(
      std::max_element(fg.begin(), fg.end(), [](const auto& x, const auto& y) { return score(x) < score(y); }) -
      fg.begin());
  // Golden section on the bracket [grid[b-1], grid[b+1]].
  double a = grid[b > 0 ? b - 1 : 0], c = grid[std::min(b + 1, grid.size() - 1)];
  const double g = (std::sqrt(5.0) - 1) / 2;
  double x1 = c - g * (c - a), x2 = a + g * (c - a);
  const std::vector<DesignEvaluation> f12 = record(evaluate(opt, {x1, x2}, "refine"));
  double f1 = score(f12[0]), f2 = score(f12[1]);
  for (int it = 0; it < opt.refine; ++it) {
    if (f1 >= f2) {
      c = x2; x2 = x1; f2 = f1;
      x1 = c - g * (c - a);
      f1 = score(record(evaluate(opt, {x1}, "refine"))[0]);
    } else {
      a = x1; x1 = x2; f1 = f2;
      x2 = a + g * (c - a);
      f2 = score(record(evaluate(opt, {x2}, "refine"))[0]);
    }
  }
  // The best of every evaluation that is not degraded, the first of equals.
  for (const DesignEvaluation& e : out.evaluations)
    if (e.degraded_reasons.empty() && (!out.found || e.objective > out.best_objective)) {
      out.found = true;
      out.best_objective = e.objective;
      out.best_value = e.value;
    }
  return out;
}

std::size_t DesignResult::degraded() const {
  return static_cast<std::size_t>(std::count_if(evaluations.begin(), evaluations.end(),
                                                [](const DesignEvaluation& e) { return !e.degraded_reasons.empty(); }));
}

json DesignResult::to_json() const {
  json evals = json::array();
  for (const DesignEvaluation& e : evaluations)
    evals.push_back({{"value", e.value},
                     {"objective", e.objective},
                     {"phase", e.phase},
                     {"status", e.degraded_reasons.empty() ? "ok" : "degraded"},
                     {"degraded_reasons", e.degraded_reasons}});
  const DesignOptions& o = options;
  const json best = found ? json{{"value", best_value}, {"objective", best_objective}} : json(nullptr);
  return {{"scene", o.scene_path}, {"key", o.key}, {"metric", o.metric}, {"objective", o.objective},
          {"records", o.records}, {"range", {o.lo, o.hi}},
          {"best", best}, {"evaluations", evals}, {"degraded", degraded()}};
}

}  // namespace vines::host
