// `vines sweep`: the runs of a spec (each its study's scene with its keys
// set), the results shared between runs, and results.csv / summary.json.
#include "sim_host/sweep.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "sim_host/build_engine.hpp"
#include "sim_host/csv.hpp"
#include "sim_host/output.hpp"
#include "sim_host/parallel.hpp"
#include "sim_host/run.hpp"
#include "sim_host/scene_limits.hpp"
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
  if (v.record_file) {  // read as vines run --record reads it: its own format, units, column, time step
    for (const char* k : {"format", "units", "dt_s", "column"}) t->erase(k);
    t->insert_or_assign(key, v.text);
  } else if (v.text == "unset") t->erase(key);
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

// Keys that only say where the device starts: runs that differ in nothing
// else share a built model.
constexpr std::string_view kInitialConditionKeys[] = {"vines.initial_position_m", "vines.initial_velocity_mps",
                                                      "tmd.initial_position_m", "tmd.initial_velocity_mps"};

// A cache key: the named tables of a run's scene as TOML text (toml++ keeps
// a table's keys sorted, so equal tables print alike), less the `drop` keys
// ("table.key"), after `prefix`.
std::string key_of(const std::string& prefix, const toml::table& doc, std::initializer_list<std::string_view> tables,
                   const std::vector<std::string_view>& drop = {}) {
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
  // A run's parameters as built: a Kuwabara scene without tau gets the one it
  // calibrates to.
  SceneParams built_params(const RunScene& r) {
    SceneParams p = r.scene.params;
    if (p.device.kind == DeviceKind::kVines && p.device.vines.law == ContactLaw::kKuwabara &&
        p.device.vines.tau_s == 0.0)
      p.device.vines.tau_s = tau(r);
    return p;
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
    p.loop.floor_peaks = false;
    std::unique_ptr<Engine> e = build(s, p);
    if (info) *info = e->info();
    return run_engine(*e, ex, stop);
  }
  static RunTotals run_engine(Engine& e, const Excitation& ex, const std::atomic<bool>* stop) {
    constexpr std::size_t kBlock = 512;
    e.init(ex.samples[0]);
    for (std::size_t k = 1; k < ex.samples.size(); k += kBlock) {
      stop_point(stop);
      e.run(ex.samples.data() + k, std::min(kBlock, ex.samples.size() - k));
    }
    return e.totals();
  }

  // A run's scene less its initial conditions, and what its runs share: the
  // excitation, the bare frame, the gap (when asked for), the parameters as
  // built (Kuwabara tau calibrated) and the key of the model they build.
  struct Base {
    RunScene run;
    SceneParams params;
    std::string model_key;
    std::shared_ptr<const Excitation> excitation;
    std::shared_ptr<const RunTotals> bare;
    double gap = 0;
  };
  // `key` names the study and `values` (no initial conditions, none scaled).
  std::shared_ptr<const Base> base(const std::string& key, const toml::table& table, const std::string& origin,
                                   const std::vector<KeyValue>& values, bool need_gap) {
    return get<Base>(bases_, key + (need_gap ? "|gap" : ""), [&] {
      Base b{scene_with(table, origin, values), {}, {}, {}, {}, 0};
      b.params = built_params(b.run);
      // The model: every table but the record's, less the initial conditions.
      b.model_key = key_of(scalar_name(b.run.scene.scalar), b.run.table, {"frame", "device", "tmd", "vines", "loop"},
                           {std::begin(kInitialConditionKeys), std::end(kInitialConditionKeys)});
      b.excitation = excitation(b.run);
      b.bare = bare(b.run);
      if (need_gap) b.gap = gap(b.run);
      return b;
    });
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
  Map<Base> bases_;
};

// Built engines between runs: a worker takes one of the model it needs (or
// builds it) and gives it back after its run; runs that differ only in
// initial conditions or in the record reuse it (Engine::set_initial_conditions)
// instead of building the model again. At most kHeld engines are kept.
class EnginePool {
 public:
  std::unique_ptr<Engine> take(const std::string& key) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = idle_.find(key);
    if (it == idle_.end() || it->second.empty()) return nullptr;
    std::unique_ptr<Engine> e = std::move(it->second.back());
    it->second.pop_back();
    --held_;
    return e;
  }
  void give(const std::string& key, std::unique_ptr<Engine> e) {
    constexpr std::size_t kHeld = 64;
    std::lock_guard<std::mutex> lock(mutex_);
    if (held_ >= kHeld) {  // many models (a grid over the design): start afresh
      idle_.clear();
      held_ = 0;
    }
    idle_[key].push_back(std::move(e));
    ++held_;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, std::vector<std::unique_ptr<Engine>>> idle_;
  std::size_t held_ = 0;
};

bool initial_condition_key(const std::string& key) {
  return std::find(std::begin(kInitialConditionKeys), std::end(kInitialConditionKeys), key) !=
         std::end(kInitialConditionKeys);
}

// Sets an initial condition in the parameters, as the scene reader does.
void set_initial_condition(SceneParams* p, const std::string& key, double x) {
  if (key == "vines.initial_position_m") {
    p->device.vines.initial_position_m = x;
    p->device.vines.start_at_left_wall = false;
  } else if (key == "vines.initial_velocity_mps") {
    p->device.vines.initial_velocity_mps = x;
  } else if (key == "tmd.initial_position_m") {
    p->device.tmd.initial_position_m = x;
  } else {
    p->device.tmd.initial_velocity_mps = x;
  }
}

// A run's figures from its totals and its bare frame's.
RunResult result_of(const RunTotals& t, const RunTotals& b, const SceneParams& p, const ModelInfo& info,
                    Scalar scalar) {
  RunResult r;
  r.device = p.device.kind == DeviceKind::kTmd ? "tmd" : p.device.kind == DeviceKind::kVines ? "vines" : "none";
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
  const RunStatus status = device_status(t, device ? &b : nullptr, p, info, scalar);
  r.degraded = !status.ok();
  r.degraded_reasons = status.codes();
  return r;
}

// Any run: its scene from the study's table with every key set (TOML), a
// model built for it.
RunResult run_general(const StudySpec& st, const RunPlan& plan, const toml::table& base, Cache& cache,
                      const std::atomic<bool>* stop) {
  // Literal values first; scaled ones need the design (gap) and the bare run (vmax).
  std::vector<KeyValue> values = st.set, scaled;
  for (const KeyValue& v : plan.values) (v.scaled() ? scaled : values).push_back(v);
  RunScene run = scene_with(base, st.scene_path, values);
  if (!scaled.empty()) {
    for (KeyValue v : scaled) {
      const std::string what = v.text.substr(6);
      v.number *= what == "gap" ? cache.gap(run) : cache.bare(run)->peak_top_velocity;
      v.text.clear();
      values.push_back(v);
    }
    run = scene_with(base, st.scene_path, values);
  }
  const SceneParams p = cache.built_params(run);
  ModelInfo info;
  const RunTotals t = Cache::run_totals(run.scene, p, *cache.excitation(run), stop, &info);
  return result_of(t, *cache.bare(run), p, info, run.scene.scalar);
}

// A run whose initial conditions are numbers and whose other keys are not
// scaled: the scene less its initial conditions is shared (one TOML pass per
// distinct set of other keys), the initial conditions go into the parameters,
// the model comes from the pool. nullopt when the parameters are refused:
// run_general then says why, in the scene's words.
std::optional<RunResult> run_shared(int study, const StudySpec& st, const RunPlan& plan, const toml::table& table,
                                    Cache& cache, EnginePool& pool, const std::atomic<bool>* stop) {
  std::vector<KeyValue> others, initial;
  std::string key = std::to_string(study);
  bool need_gap = false;
  for (const std::vector<KeyValue>* list : {&st.set, &plan.values})
    for (const KeyValue& v : *list) {
      if (initial_condition_key(v.key) && (v.text.empty() || v.scaled())) {
        initial.push_back(v);
        need_gap |= v.text == "scale:gap";
      } else if (v.scaled()) {
        return run_general(st, plan, table, cache, stop);
      } else {
        others.push_back(v);
        key += '|' + v.key + '=' + (v.text.empty() ? v.label() : (v.record_file ? "file:\"" : "\"") + v.text + '"');
      }
    }
  std::shared_ptr<const Cache::Base> b;
  try {
    b = cache.base(key, table, st.scene_path, others, need_gap);
  } catch (const std::exception&) {
    return std::nullopt;  // refused: in the words of the whole scene
  }
  // The scene's parameters (as read, and as built) with the initial conditions set.
  SceneParams read = b->run.scene.params, p = b->params;
  for (const KeyValue& v : initial) {
    const double scale = v.text == "scale:gap" ? b->gap : v.text == "scale:vmax" ? b->bare->peak_top_velocity : 1.0;
    set_initial_condition(&read, v.key, v.number * scale);
    set_initial_condition(&p, v.key, v.number * scale);
  }
  // The checks the scene reader makes of these keys; the contact scales read
  // the initial speed only through this speed (scene_limits.cpp), checked
  // already for the scene when it is the same.
  auto speed = [](const SceneParams& q) {
    const VinesParams& v = q.device.vines;
    return std::max({v.v_ref_mps, std::fabs(v.initial_velocity_mps), kMinRepresentativeSpeed});
  };
  if (!validate(read).ok() || (speed(read) != speed(b->run.scene.params) && check_contact_scales(read)))
    return std::nullopt;
  std::unique_ptr<Engine> e = pool.take(b->model_key);
  if (e && !e->set_initial_conditions(p).ok()) {
    pool.give(b->model_key, std::move(e));
    return std::nullopt;
  }
  if (!e) {
    SceneParams built = p;
    built.loop.floor_peaks = false;
    e = make_engine(built, b->run.scene.scalar);
    if (!e || !e->build(built).ok()) return std::nullopt;
  }
  const ModelInfo info = e->info();
  const RunTotals t = Cache::run_engine(*e, *b->excitation, stop);
  pool.give(b->model_key, std::move(e));
  return result_of(t, *b->bare, p, info, b->run.scene.scalar);
}

// A run, or Stopped once *stop is set.
RunResult run_one(const SweepSpec& spec, const RunPlan& plan, const std::vector<toml::table>& bases,
                  Cache& cache, EnginePool& pool, const std::atomic<bool>* stop) {
  const StudySpec& st = spec.studies[plan.study];
  RunResult r;
  try {
    std::optional<RunResult> shared = run_shared(plan.study, st, plan, bases[plan.study], cache, pool, stop);
    r = shared ? *shared : run_general(st, plan, bases[plan.study], cache, stop);
  } catch (const std::exception& e) {
    r = RunResult{};
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

std::vector<RunResult> execute(const SweepSpec& spec, const std::vector<RunPlan>& plan, int threads,
                               int offset, int stride, const std::atomic<bool>* stop, bool progress,
                               SweepLog* log, std::vector<RunResult> finished) {
  std::vector<toml::table> bases;
  for (const StudySpec& st : spec.studies)
    bases.push_back(st.scene_toml.empty() ? read_scene_table(st.scene_path)
                                          : parse_scene_table(st.scene_toml, st.scene_path));
  std::vector<RunResult> results = finished.empty() ? std::vector<RunResult>(plan.size()) : std::move(finished);
  // This rank's runs not yet done: every stride-th from offset, each stored at its index.
  std::vector<std::size_t> mine;
  for (std::size_t i = static_cast<std::size_t>(offset); i < plan.size(); i += static_cast<std::size_t>(stride))
    if (!results[i].done) mine.push_back(i);
  Cache cache(stop);
  EnginePool pool;
  parallel_map(mine.size(), MapOptions{threads, stop, progress, "sweep", "runs"}, [&](std::size_t k) {
    results[mine[k]] = run_one(spec, plan[mine[k]], bases, cache, pool, stop);
    if (log != nullptr) log->append(mine[k], results[mine[k]]);
  });
  return results;
}

SweepSummary write_sweep(const SweepSpec& spec, const std::vector<RunPlan>& plan,
                         const std::vector<RunResult>& results, const std::string& out_dir, double wall_s,
                         int cores) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create: " + ec.message());
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
