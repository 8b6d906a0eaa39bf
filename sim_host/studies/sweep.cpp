// `vines sweep`: the runs of a spec (each its study's scene with its keys
// set) and the results shared between runs (sweep_results.cpp writes them).
#include "sim_host/studies/sweep.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <map>
#include <mutex>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/run/drive.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/run/status.hpp"
#include "sim_host/scene/limits.hpp"
#include "sim_host/scene/table.hpp"
#include "sim_host/studies/parallel.hpp"
#include "sim_host/studies/sweep_log.hpp"
#include "sim_host/studies/sweep_scene.hpp"

namespace vines::host {
namespace {

// Keys that only say where the device starts: runs that differ in nothing
// else share a built model.
constexpr std::string_view kInitialConditionKeys[] = {"vines.initial_position_m", "vines.initial_velocity_mps",
                                                      "tmd.initial_position_m", "tmd.initial_velocity_mps"};

// Results shared between runs: excitations, bare frames, VI NES designs (a
// law's calibration), VI NES free travel; each keyed on every scene input it depends on.
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
                                    "loop.contact_scheme", "loop.bounded_substeps", "loop.split_steps",
                                    "loop.floor_peaks", "loop.fixed_contact_speed_mps"});
    return get<RunTotals>(bares_, key, [&] { return run_totals(r.scene, p, *excitation(r), stop_); });
  }
  // The VI NES design a scene builds (its law's calibration: the same for
  // every initial condition).
  VinesDesign design(const RunScene& r) {
    SceneParams p = r.scene.params;
    p.device.vines.initial_position_m = p.device.vines.initial_velocity_mps = 0;
    p.device.vines.start_at_left_wall = true;
    const std::string key = key_of(scalar_name(r.scene.scalar), r.table, {"frame", "device", "vines", "loop"},
                                   {"vines.initial_position_m", "vines.initial_velocity_mps"});
    return *get<VinesDesign>(designs_, key, [&] { return build(r.scene, p)->info().vines; });
  }
  // A run's parameters as built: a VI NES scene keeps its law's calibration
  // (law_keep: Kuwabara's tau).
  SceneParams built_params(const RunScene& r) {
    SceneParams p = r.scene.params;
    if (p.device.kind == DeviceKind::kVines) law_keep(design(r), &p.device.vines);
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
    refuse_damage(s, "vines sweep / design");
    return build_engine(p, s.scalar, s.path);
  }
  // A study run: its figures need the top floor and E_e, not every floor.
  // The samples go through drive(), with a stop check between its blocks
  // (*info: the model, when asked for).
  static RunTotals run_totals(const Scene& s, SceneParams p, const Excitation& ex, const std::atomic<bool>* stop,
                              ModelInfo* info = nullptr) {
    p.loop.floor_peaks = false;
    std::unique_ptr<Engine> e = build(s, p);
    if (info) *info = e->info();
    return run_engine(*e, ex, stop);
  }
  static RunTotals run_engine(Engine& e, const Excitation& ex, const std::atomic<bool>* stop) {
    hal::RecordSource src(ex.samples, ex.rate_hz);
    if (drive(e, src, stop) < ex.samples.size()) stop_point(stop);  // stopped part way
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
  Map<VinesDesign> designs_;
  Map<double> gaps_;
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

}  // namespace

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

}  // namespace vines::host
