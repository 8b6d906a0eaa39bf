// `vines sweep`: the runs of a spec (each its study's scene with its keys
// set), the results shared between runs, and results.csv / summary.json.
#include "sim_host/sweep.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "sim_host/build_engine.hpp"
#include "sim_host/csv.hpp"
#include "sim_host/output.hpp"
#include "sim_host/parallel.hpp"
#include "sim_host/run.hpp"
#include "sim_host/scene_toml.hpp"
#include "sim_host/sweep_log.hpp"
#include "sim_host/status.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- scenes of a run ----

// Sets (or removes) a dotted key "table.key" in a scene's table.
void set_key(toml::table& root, const KeyValue& v) {
  const auto dot = v.key.find('.');
  const std::string table = v.key.substr(0, dot), key = v.key.substr(dot + 1);
  toml::table* t = root[table].as_table();
  if (!t) t = root.insert_or_assign(table, toml::table{}).first->second.as_table();
  if (v.text == "unset") t->erase(key);
  else if (v.text == "true" || v.text == "false") t->insert_or_assign(key, v.text == "true");
  else if (!v.text.empty()) t->insert_or_assign(key, v.text);
  else if (v.integral) t->insert_or_assign(key, static_cast<int64_t>(std::llround(v.number)));
  else t->insert_or_assign(key, v.number);
}

// A run's scene: the study's table with the run's keys set, and the Scene
// checked from it.
struct RunScene {
  toml::table table;
  Scene scene;
};

RunScene scene_with(const toml::table& base, const std::string& origin, const std::vector<KeyValue>& values) {
  RunScene r{base, {}};
  for (const KeyValue& v : values) set_key(r.table, v);
  r.scene = scene_from_table(r.table, origin);
  return r;
}

// A cache key: the named tables of a run's scene as TOML text (toml++ keeps
// a table's keys sorted, so equal tables print alike), less the `drop` keys
// ("table.key"), after `prefix`.
std::string key_of(const std::string& prefix, const toml::table& doc, std::initializer_list<std::string_view> tables,
                   std::initializer_list<std::string_view> drop = {}) {
  toml::table part;
  for (std::string_view t : tables)
    if (const toml::node* n = doc.get(t)) part.insert(t, *n);
  for (std::string_view d : drop) {
    const std::size_t dot = d.find('.');
    if (toml::table* t = part[d.substr(0, dot)].as_table()) t->erase(d.substr(dot + 1));
  }
  std::ostringstream k;
  k << prefix << '|' << part;
  return k.str();
}

// Results shared between runs: excitations, bare frames, Kuwabara tau, VI
// NES free travel; each keyed on every scene input it depends on.
class Cache {
 public:
  explicit Cache(const std::atomic<bool>* stop) : stop_(stop) {}

  std::shared_ptr<const Excitation> excitation(const RunScene& r) {
    return get<Excitation>(excitations_, record_key(r), [&] { return load_excitation(r.scene, ""); });
  }
  std::shared_ptr<const RunTotals> bare(const RunScene& r) {
    SceneParams p = r.scene.params;
    p.device.kind = DeviceKind::kNone;
    // Keyed on the frame and the loop (scalar, divergence limit, ledger) less
    // the keys only contacts read.
    const std::string key = key_of(record_key(r), r.table, {"frame", "loop"},
                                   {"loop.contact_rtol", "loop.max_substeps_per_step", "loop.contact_count_depth_m",
                                    "loop.contact_scheme", "loop.bounded_substeps", "loop.floor_peaks"});
    return get<RunTotals>(bares_, key, [&] { return run_totals(r.scene, p, *excitation(r), stop_); });
  }
  // The tau a Kuwabara scene calibrates to (same for every initial condition).
  double tau(const RunScene& r) {
    SceneParams p = r.scene.params;
    p.device.vines.initial_position_m = p.device.vines.initial_velocity_mps = 0;
    p.device.vines.start_at_left_wall = true;
    const std::string key = key_of(scalar_name(r.scene.scalar), r.table, {"frame", "device", "vines", "loop"},
                                   {"vines.initial_position_m", "vines.initial_velocity_mps"});
    return *get<double>(taus_, key, [&] { return build(r.scene, p)->info().vines.tau; });
  }
  // VI NES free travel of a scene's design.
  double gap(const RunScene& r) {
    SceneParams p = r.scene.params;
    p.device.kind = DeviceKind::kVines;
    p.device.vines.start_at_left_wall = true;
    const std::string key = key_of(scalar_name(r.scene.scalar), r.table, {"frame", "device", "vines"},
                                   {"device.kind", "vines.initial_position_m", "vines.initial_velocity_mps"});
    return *get<double>(gaps_, key, [&] { return build(r.scene, p)->info().vines.gap; });
  }

  static std::unique_ptr<Engine> build(const Scene& s, const SceneParams& p) {
    return build_engine(p, s.scalar, s.path);
  }
  // A study run: its figures need the top floor and E_e, not every floor.
  // The samples go in blocks (the same result, bit for bit, as one call),
  // with a stop check between blocks (*info: the model, when asked for).
  static RunTotals run_totals(const Scene& s, SceneParams p, const Excitation& ex, const std::atomic<bool>* stop,
                              ModelInfo* info = nullptr) {
    constexpr std::size_t kBlock = 512;
    p.loop.floor_peaks = false;
    std::unique_ptr<Engine> e = build(s, p);
    if (info) *info = e->info();
    e->init(ex.samples[0]);
    for (std::size_t k = 1; k < ex.samples.size(); k += kBlock) {
      stop_point(stop);
      e->run(ex.samples.data() + k, std::min(kBlock, ex.samples.size() - k));
    }
    return e->totals();
  }

 private:
  template <typename T>
  using Map = std::map<std::string, std::shared_future<std::shared_ptr<const T>>>;

  // Computes each key once, whichever thread asks first; the others wait.
  template <typename T, typename F>
  std::shared_ptr<const T> get(Map<T>& map, const std::string& key, F&& make) {
    std::promise<std::shared_ptr<const T>> promise;
    std::shared_future<std::shared_ptr<const T>> fut;
    bool mine = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = map.find(key);
      if (it == map.end()) {
        fut = promise.get_future().share();
        map.emplace(key, fut);
        mine = true;
      } else {
        fut = it->second;
      }
    }
    if (mine) {
      try {
        promise.set_value(std::make_shared<const T>(make()));
      } catch (...) {
        promise.set_exception(std::current_exception());
      }
    }
    return fut.get();
  }
  // The record as loaded: the [record] table, where a relative path is
  // looked for (the scene file), and the sensor rate it is resampled to.
  static std::string record_key(const RunScene& r) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%a", r.scene.params.loop.sensor_rate_hz);
    return key_of(r.scene.path + '|' + rate, r.table, {"record"});
  }

  const std::atomic<bool>* stop_;
  std::mutex mutex_;
  Map<Excitation> excitations_;
  Map<RunTotals> bares_;
  Map<double> taus_, gaps_;
};

// A run, or Stopped once *stop is set.
RunResult run_one(const SweepSpec& spec, const RunPlan& plan, const std::vector<toml::table>& bases,
                  Cache& cache, const std::atomic<bool>* stop) {
  const StudySpec& st = spec.studies[plan.study];
  RunResult r;
  try {
    // Literal values first; scaled ones need the design (gap) and the bare run (vmax).
    std::vector<KeyValue> values = st.set, scaled;
    for (const KeyValue& v : plan.values) (v.scaled() ? scaled : values).push_back(v);
    RunScene run = scene_with(bases[plan.study], st.scene_path, values);
    if (!scaled.empty()) {
      for (KeyValue v : scaled) {
        const std::string what = v.text.substr(6);
        v.number *= what == "gap" ? cache.gap(run) : cache.bare(run)->peak_top_velocity;
        v.text.clear();
        values.push_back(v);
      }
      run = scene_with(bases[plan.study], st.scene_path, values);
    }
    SceneParams p = run.scene.params;
    r.device = p.device.kind == DeviceKind::kTmd ? "tmd" : p.device.kind == DeviceKind::kVines ? "vines" : "none";
    if (p.device.kind == DeviceKind::kVines && p.device.vines.law == ContactLaw::kKuwabara &&
        p.device.vines.tau_s == 0.0)
      p.device.vines.tau_s = cache.tau(run);
    ModelInfo info;
    const RunTotals t = Cache::run_totals(run.scene, p, *cache.excitation(run), stop, &info);
    const RunTotals& b = *cache.bare(run);
    r.peak_top = t.peak_top;
    r.elastic_energy = t.elastic_energy;
    r.x_r = reduction(b.peak_top, t.peak_top);
    r.E_r = reduction(b.elastic_energy, t.elastic_energy);
    r.residual = t.ledger.relative_residual();
    r.contacts = t.count.contacts;
    // The guards of both runs, and the status (a device run is compared with its bare frame).
    const bool device = p.device.kind != DeviceKind::kNone;
    r.cap_hits = t.count.cap_hits;
    r.bad_samples = t.count.bad_samples + (device ? b.count.bad_samples : 0);
    r.divergences = t.count.divergences + (device ? b.count.divergences : 0);
    r.max_overlap = t.max_overlap;
    r.energy_checked = p.loop.energy_ledger;
    const RunStatus status = device_status(t, device ? &b : nullptr, p, info, run.scene.scalar);
    r.degraded = !status.ok();
    r.degraded_reasons = status.codes();
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  r.done = true;
  return r;
}

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
  std::map<double, Figures> groups;
  const std::string gkey = !st.group_by.empty() ? st.group_by
                           : (!st.optimize.empty() && st.grid_axes.size() == 1) ? st.grid_axes[0].front().key
                                                                                  : "";
  for (std::size_t i = 0; i < plan.size(); ++i) {
    if (plan[i].study != s || !results[i].done || !results[i].error.empty()) continue;
    all.add(results[i]);
    out.device = results[i].device;
    out.energy_checked &= results[i].energy_checked;
    for (const KeyValue& v : plan[i].values)
      if (v.key == gkey) groups[v.number].add(results[i]);
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
    out.groups.push_back({value, stats(g.xr), stats(g.er), g.degraded});
    const std::optional<Stats>& m = st.optimize == "E_r" ? out.groups.back().E_r : out.groups.back().x_r;
    if (m && m->mean > out.best) {
      out.best = m->mean;
      out.best_value = value;
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
        jg.push_back({{"value", g.value}, {"x_r", stats_json(g.x_r)}, {"E_r", stats_json(g.E_r)},
                      {"degraded", g.degraded}});
      j["group_by"] = st.group_by;
      j["groups"] = jg;
      if (!st.optimize.empty()) j["best"] = {{"key", st.group_by}, {"value", st.best_value}, {st.optimize, st.best}};
    }
    js.push_back(j);
  }
  return {{"spec", spec},   {"runs", runs},           {"done", done},
          {"failed", failed}, {"complete", done == runs}, {"wall_time_s", wall_s},
          {"runs_per_s", runs_per_s()}, {"studies", js}, {"degraded", degraded}};
}

std::vector<RunResult> execute(const SweepSpec& spec, const std::vector<RunPlan>& plan, int threads,
                               int offset, int stride, const std::atomic<bool>* stop, bool progress,
                               SweepLog* log, std::vector<RunResult> finished) {
  std::vector<toml::table> bases;
  for (const StudySpec& st : spec.studies) bases.push_back(read_scene_table(st.scene_path));
  std::vector<RunResult> results = finished.empty() ? std::vector<RunResult>(plan.size()) : std::move(finished);
  // This rank's runs not yet done: every stride-th from offset, each stored at its index.
  std::vector<std::size_t> mine;
  for (std::size_t i = static_cast<std::size_t>(offset); i < plan.size(); i += static_cast<std::size_t>(stride))
    if (!results[i].done) mine.push_back(i);
  Cache cache(stop);
  parallel_map(mine.size(), MapOptions{threads, stop, progress, "sweep", "runs"}, [&](std::size_t k) {
    results[mine[k]] = run_one(spec, plan[mine[k]], bases, cache, stop);
    if (log != nullptr) log->append(mine[k], results[mine[k]]);
  });
  return results;
}

SweepSummary write_sweep(const SweepSpec& spec, const std::vector<RunPlan>& plan,
                         const std::vector<RunResult>& results, const std::string& out_dir, double wall_s) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create: " + ec.message());
  write_results_csv(spec, plan, results, fs::path(out_dir) / "results.csv");
  SweepSummary s;
  s.spec = spec.path;
  s.runs = plan.size();
  s.wall_s = wall_s;
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
