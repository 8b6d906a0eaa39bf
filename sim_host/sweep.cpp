#include "sim_host/sweep.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <unistd.h>

#include "sim_host/engine.hpp"
#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

// ---- spec parsing ----

// A grid value list: explicit values, a range table, or a list mixing both.
struct Scaled {
  std::vector<KeyValue> values;
  std::string scale;  // "", "gap" or "vmax"
};

KeyValue value_of(const std::string& where, const std::string& key, const toml::node& n) {
  KeyValue v;
  v.key = key;
  if (auto i = n.as_integer()) {
    v.number = static_cast<double>(i->get());
    v.integral = true;
  } else if (auto f = n.as_floating_point()) {
    v.number = f->get();
  } else if (auto s = n.as_string()) {
    v.text = s->get();
  } else if (auto b = n.as_boolean()) {
    v.text = b->get() ? "true" : "false";
  } else {
    fail(where, key + ": values must be numbers, strings or booleans");
  }
  return v;
}

// Values of a range table {from, to, step | count, scale}.
std::vector<double> range_values(const std::string& where, const std::string& key,
                                 const toml::table& t, std::string* scale, bool* integral) {
  for (auto&& kv : t)
    if (kv.first != "from" && kv.first != "to" && kv.first != "step" && kv.first != "count" &&
        kv.first != "scale")
      fail(where, key + ": unknown range key '" + std::string(kv.first.str()) +
                      "' (known: from, to, step, count, scale)");
  const auto from = t["from"].value<double>(), to = t["to"].value<double>();
  if (!from || !to) fail(where, key + ": a range needs numbers 'from' and 'to'");
  if (auto s = t["scale"].value<std::string>()) {
    if (*s != "gap" && *s != "vmax") fail(where, key + ": scale must be \"gap\" or \"vmax\"");
    *scale = *s;
  }
  *integral = t["from"].is_integer() && t["to"].is_integer() && t["step"].is_integer();
  std::vector<double> out;
  if (auto step = t["step"].value<double>()) {
    if (!(*step > 0)) fail(where, key + ": step must be > 0");
    const double n = std::floor((*to - *from) / *step + 1e-9);
    if (n < 0 || n > 1e6) fail(where, key + ": empty or huge range");
    for (int i = 0; i <= static_cast<int>(n); ++i) {
      const double x = *from + i * *step;
      out.push_back(std::round(x * 1e12) / 1e12);  // 1.05 + 3 * 0.05 prints as 1.2
    }
  } else if (auto count = t["count"].value<int64_t>()) {
    if (*count < 1 || *count > 1000000) fail(where, key + ": count must be in [1, 1e6]");
    for (int64_t i = 0; i < *count; ++i)
      out.push_back(*count == 1 ? *from : *from + (*to - *from) * static_cast<double>(i) / (*count - 1));
  } else {
    fail(where, key + ": a range needs 'step' or 'count'");
  }
  return out;
}

Scaled grid_axis(const std::string& where, const std::string& key, const toml::node& n) {
  Scaled ax;
  std::vector<double> numbers;
  bool all_integral = true;
  auto add_range = [&](const toml::table& t) {
    std::string scale;
    bool integral = false;
    for (double x : range_values(where, key, t, &scale, &integral)) numbers.push_back(x);
    all_integral &= integral;
    if (!ax.scale.empty() && ax.scale != scale) fail(where, key + ": ranges with different scales");
    ax.scale = scale;
  };
  if (auto t = n.as_table()) {
    add_range(*t);
  } else if (auto a = n.as_array()) {
    for (auto&& e : *a) {
      if (auto tt = e.as_table()) {
        add_range(*tt);
      } else {
        KeyValue v = value_of(where, key, e);
        if (!v.text.empty()) ax.values.push_back(v);
        else { numbers.push_back(v.number); all_integral &= v.integral; }
      }
    }
  } else {
    fail(where, key + ": a grid key takes a list of values or a range table");
  }
  // Union of the numbers, sorted, without duplicates.
  std::sort(numbers.begin(), numbers.end());
  numbers.erase(std::unique(numbers.begin(), numbers.end(),
                            [](double a, double b) { return std::fabs(a - b) <= 1e-12 * (1 + std::fabs(a)); }),
                numbers.end());
  for (double x : numbers) {
    KeyValue v;
    v.key = key;
    v.number = x;
    v.integral = all_integral && ax.scale.empty();
    ax.values.push_back(v);
  }
  if (ax.values.empty()) fail(where, key + ": no values");
  return ax;
}

void check_keys(const std::string& where, const toml::table& t,
                std::initializer_list<std::string_view> known) {
  for (auto&& kv : t)
    if (std::find(known.begin(), known.end(), kv.first.str()) == known.end())
      fail(where, "unknown key '" + std::string(kv.first.str()) + "'");
}

std::vector<KeyValue> key_values(const std::string& where, const toml::table& t) {
  std::vector<KeyValue> out;
  for (auto&& kv : t) out.push_back(value_of(where, std::string(kv.first.str()), kv.second));
  return out;
}

// ---- scenes of a run ----

// Sets (or removes) a dotted key "table.key" in a TOML document.
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

Scene scene_with(const toml::table& base, const std::string& origin, const std::vector<KeyValue>& values) {
  toml::table doc = base;
  for (const KeyValue& v : values) set_key(doc, v);
  std::ostringstream text;
  text << doc;
  return parse_scene(text.str(), origin);
}

// Results shared between runs: excitations, bare frames, Kuwabara tau.
class Cache {
 public:
  std::shared_ptr<const Excitation> excitation(const Scene& s) {
    return get<Excitation>(excitations_, record_key(s), [&] { return load_excitation(s, ""); });
  }
  std::shared_ptr<const RunTotals> bare(const Scene& s) {
    SceneParams p = s.params;
    p.device.kind = DeviceKind::kNone;
    return get<RunTotals>(bares_, record_key(s) + bytes(p.frame) + scalar_name(s.scalar), [&] {
      return run_totals(s, p, *excitation(s));
    });
  }
  // The tau a Kuwabara scene calibrates to (same for every initial condition).
  double tau(const Scene& s) {
    SceneParams p = s.params;
    p.device.vines.initial_position_m = p.device.vines.initial_velocity_mps = 0;
    p.device.vines.start_at_left_wall = true;
    const std::string key = bytes(p.frame) + bytes(p.device) + bytes(p.loop);
    return *get<double>(taus_, key, [&] { return build(s, p)->info().vines.tau; });
  }
  // VI NES free travel of a scene's design.
  double gap(const Scene& s) {
    SceneParams p = s.params;
    p.device.kind = DeviceKind::kVines;
    p.device.vines.start_at_left_wall = true;
    return *get<double>(gaps_, bytes(p.frame) + bytes(p.device), [&] { return build(s, p)->info().vines.gap; });
  }

  static std::unique_ptr<Engine> build(const Scene& s, const SceneParams& p) {
    std::unique_ptr<Engine> e = make_engine(p, s.scalar);
    if (!e) fail(s.path, "frame.stories: " + missing_engine(p, s.scalar));
    const ParamError err = e->build(p);
    if (!err.ok()) fail(s.path, std::string(err.field) + ": " + err.message);
    return e;
  }
  // A study run: its figures need the top floor and E_e, not every floor.
  static RunTotals run_totals(const Scene& s, SceneParams p, const Excitation& ex) {
    p.loop.floor_peaks = false;
    std::unique_ptr<Engine> e = build(s, p);
    e->init(ex.samples[0]);
    e->run(ex.samples.data() + 1, ex.samples.size() - 1);
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
  template <typename T>
  static std::string bytes(const T& v) {
    return std::string(reinterpret_cast<const char*>(&v), sizeof v);
  }
  static std::string record_key(const Scene& s) {
    const hal::RecordSpec& r = s.record;
    std::ostringstream k;
    k << r.path << '|' << static_cast<int>(r.format) << static_cast<int>(r.units) << '|' << r.dt_s
      << '|' << r.column << '|' << r.scale << '|' << s.target_pga_mps2 << '|'
      << s.params.loop.sensor_rate_hz << '|' << s.duration_s << '|' << s.path;
    return k.str();
  }

  std::mutex mutex_;
  Map<Excitation> excitations_;
  Map<RunTotals> bares_;
  Map<double> taus_, gaps_;
};

RunResult run_one(const SweepSpec& spec, const RunPlan& plan, const std::vector<toml::table>& bases,
                  Cache& cache) {
  const StudySpec& st = spec.studies[plan.study];
  RunResult r;
  try {
    // Literal values first; scaled ones need the design (gap) and the bare run (vmax).
    std::vector<KeyValue> values = st.set, scaled;
    for (const KeyValue& v : plan.values) (v.scaled() ? scaled : values).push_back(v);
    Scene scene = scene_with(bases[plan.study], st.scene_path, values);
    if (!scaled.empty()) {
      for (KeyValue v : scaled) {
        const std::string what = v.text.substr(6);
        v.number *= what == "gap" ? cache.gap(scene) : cache.bare(scene)->peak_top_velocity;
        v.text.clear();
        values.push_back(v);
      }
      scene = scene_with(bases[plan.study], st.scene_path, values);
    }
    SceneParams p = scene.params;
    r.device = p.device.kind == DeviceKind::kTmd ? "tmd" : p.device.kind == DeviceKind::kVines ? "vines" : "none";
    if (p.device.kind == DeviceKind::kVines && p.device.vines.law == ContactLaw::kKuwabara &&
        p.device.vines.tau_s == 0.0)
      p.device.vines.tau_s = cache.tau(scene);
    const RunTotals t = Cache::run_totals(scene, p, *cache.excitation(scene));
    const RunTotals& b = *cache.bare(scene);
    r.peak_top = t.peak_top;
    r.elastic_energy = t.elastic_energy;
    r.x_r = (b.peak_top - t.peak_top) / b.peak_top;
    r.E_r = (b.elastic_energy - t.elastic_energy) / b.elastic_energy;
    r.residual = t.ledger.relative_residual();
    r.contacts = t.count.contacts;
    r.cap_hits = t.count.cap_hits;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  r.done = true;
  return r;
}

// ---- statistics ----

json stats(const std::vector<double>& v) {
  if (v.empty()) return nullptr;
  double mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  const double sd = v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : 0.0;
  return {{"mean", mean}, {"sd", sd}, {"min", *std::min_element(v.begin(), v.end())},
          {"max", *std::max_element(v.begin(), v.end())}, {"n", v.size()}};
}

}  // namespace

std::string KeyValue::column() const { return scaled() ? key + "/" + text.substr(6) : key; }

std::string KeyValue::label() const {
  if (!text.empty() && !scaled()) return text;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", number);
  return buf;
}

// ---- spec file ----
SweepSpec load_sweep(const std::string& path) {
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    fail(path + ":" + std::to_string(e.source().begin.line), "TOML syntax error: " + std::string(e.description()));
  }
  check_keys(path, root, {"study"});
  const toml::array* studies = root["study"].as_array();
  if (!studies || studies->empty()) fail(path, "needs at least one [[study]]");
  SweepSpec spec;
  spec.path = path;
  for (auto&& node : *studies) {
    const toml::table* t = node.as_table();
    if (!t) fail(path, "study: must be a table");
    const std::string where = path + ":" + std::to_string(t->source().begin.line);
    check_keys(where, *t, {"name", "scene", "group_by", "optimize", "set", "cases", "grid"});
    StudySpec st;
    st.name = t->at_path("name").value_or(std::string("study") + std::to_string(spec.studies.size() + 1));
    const auto scene = t->at_path("scene").value<std::string>();
    if (!scene) fail(where, "study '" + st.name + "': needs scene = \"file.toml\"");
    st.scene_path = (fs::path(path).parent_path() / *scene).lexically_normal().string();
    st.group_by = t->at_path("group_by").value_or(std::string());
    st.optimize = t->at_path("optimize").value_or(std::string());
    if (!st.optimize.empty() && st.optimize != "x_r" && st.optimize != "E_r")
      fail(where, "optimize must be \"x_r\" or \"E_r\"");
    if (auto s = t->at_path("set").as_table()) st.set = key_values(where, *s);
    if (auto c = t->at_path("cases").as_array())
      for (auto&& e : *c) {
        if (!e.as_table()) fail(where, "cases: each case is a table of key = value");
        st.cases.push_back(key_values(where, *e.as_table()));
      }
    if (auto g = t->at_path("grid").as_table())
      for (auto&& kv : *g) {
        Scaled ax = grid_axis(where, std::string(kv.first.str()), kv.second);
        if (!ax.scale.empty())
          for (KeyValue& v : ax.values) v.text = "scale:" + ax.scale;
        st.grid_axes.push_back(ax.values);
      }
    // Every key this study sets (fixed, per case, per grid axis) is a scene key.
    auto check_key = [&](const KeyValue& v) {
      if (v.key.find('.') == std::string::npos) fail(where, v.key + ": keys are table.key");
    };
    for (const KeyValue& v : st.set) check_key(v);
    for (const auto& c : st.cases)
      for (const KeyValue& v : c) check_key(v);
    for (const auto& ax : st.grid_axes) check_key(ax.front());
    if (!st.group_by.empty()) {
      bool found = false;
      for (const auto& ax : st.grid_axes) found |= ax.front().key == st.group_by;
      if (!found) fail(where, "group_by '" + st.group_by + "' is not a grid key");
    }
    spec.studies.push_back(st);
  }
  // Every study's scene must load with its fixed overrides.
  for (const StudySpec& st : spec.studies) load_scene(st.scene_path);
  return spec;
}

std::vector<RunPlan> plan_runs(const SweepSpec& spec) {
  std::vector<RunPlan> out;
  for (int s = 0; s < static_cast<int>(spec.studies.size()); ++s) {
    const StudySpec& st = spec.studies[s];
    const std::vector<std::vector<KeyValue>> cases = st.cases.empty() ? std::vector<std::vector<KeyValue>>{{}} : st.cases;
    for (const auto& c : cases) {
      // Odometer over the grid axes, last axis fastest.
      std::vector<std::size_t> idx(st.grid_axes.size(), 0);
      while (true) {
        RunPlan r{s, c};
        for (std::size_t a = 0; a < idx.size(); ++a) r.values.push_back(st.grid_axes[a][idx[a]]);
        out.push_back(r);
        std::size_t a = idx.size();
        while (a > 0 && ++idx[a - 1] == st.grid_axes[a - 1].size()) idx[--a] = 0;
        if (a == 0) break;
      }
    }
  }
  return out;
}

std::vector<RunResult> execute(const SweepSpec& spec, const std::vector<RunPlan>& plan, int threads,
                               int offset, int stride, const std::atomic<bool>* stop, bool progress) {
  std::vector<toml::table> bases;
  for (const StudySpec& st : spec.studies) bases.push_back(toml::parse_file(st.scene_path));
  std::vector<RunResult> results(plan.size());
  std::vector<std::size_t> mine;
  for (std::size_t i = static_cast<std::size_t>(offset); i < plan.size(); i += static_cast<std::size_t>(stride))
    mine.push_back(i);
  Cache cache;
  std::atomic<std::size_t> next{0}, finished{0};
  const bool tty = progress && isatty(fileno(stderr));
  const auto t0 = std::chrono::steady_clock::now();
  std::mutex print_mutex;
  auto report = [&](std::size_t done) {
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double eta = done ? el / static_cast<double>(done) * static_cast<double>(mine.size() - done) : 0.0;
    std::lock_guard<std::mutex> lock(print_mutex);
    if (tty) {
      const int width = 30, fill = static_cast<int>(width * done / std::max<std::size_t>(mine.size(), 1));
      std::fprintf(stderr, "\r[%s%s] %zu/%zu  %.1f s elapsed, ETA %.1f s ", std::string(fill, '#').c_str(),
                   std::string(width - fill, '.').c_str(), done, mine.size(), el, eta);
      if (done == mine.size()) std::fputc('\n', stderr);
    } else if (progress) {
      std::fprintf(stderr, "sweep: %zu/%zu runs, %.1f s elapsed, ETA %.1f s\n", done, mine.size(), el, eta);
    }
  };
  const std::size_t every = std::max<std::size_t>(1, mine.size() / (tty ? 200 : 10));
  auto worker = [&] {
    for (;;) {
      if (stop && stop->load()) return;
      const std::size_t k = next.fetch_add(1);
      if (k >= mine.size()) return;
      results[mine[k]] = run_one(spec, plan[mine[k]], bases, cache);
      const std::size_t done = ++finished;
      if (progress && (done % every == 0 || done == mine.size())) report(done);
    }
  };
  const int n = threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (int i = 1; i < n; ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return results;
}

json write_sweep(const SweepSpec& spec, const std::vector<RunPlan>& plan,
                 const std::vector<RunResult>& results, const std::string& out_dir, double wall_s) {
  // Columns: every key any study varies, in order of first appearance.
  std::vector<std::string> keys;
  for (const RunPlan& r : plan)
    for (const KeyValue& v : r.values)
      if (std::find(keys.begin(), keys.end(), v.column()) == keys.end()) keys.push_back(v.column());
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) fail(out_dir, "cannot create: " + ec.message());
  std::ofstream csv(fs::path(out_dir) / "results.csv");
  if (!csv) fail(out_dir + "/results.csv", "cannot write");
  csv << "study,run,device";
  for (const std::string& k : keys) csv << ',' << k;
  csv << ",x_r,E_r,peak_top_displacement_m,elastic_energy_integral,contacts,energy_balance_residual,"
         "substep_cap_hits,error\n";
  char buf[256];
  std::size_t done = 0, failed = 0;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const RunResult& r = results[i];
    if (!r.done) continue;
    ++done;
    failed += !r.error.empty();
    csv << spec.studies[plan[i].study].name << ',' << i << ',' << r.device;
    for (const std::string& k : keys) {
      csv << ',';
      for (const KeyValue& v : plan[i].values)
        if (v.column() == k) csv << v.label();
    }
    if (r.error.empty()) {
      std::snprintf(buf, sizeof buf, ",%.10g,%.10g,%.10g,%.10g,%lld,%.3g,%lld,", r.x_r, r.E_r, r.peak_top,
                    r.elastic_energy, r.contacts, r.residual, r.cap_hits);
      csv << buf << '\n';
    } else {
      std::string e = r.error;
      std::replace(e.begin(), e.end(), '"', '\'');
      csv << ",,,,,,,,\"" << e << "\"\n";
    }
  }

  json studies = json::array();
  for (int s = 0; s < static_cast<int>(spec.studies.size()); ++s) {
    const StudySpec& st = spec.studies[s];
    std::vector<double> xr, er;
    std::map<double, std::pair<std::vector<double>, std::vector<double>>> groups;
    std::map<double, std::string> group_labels;
    std::string device;
    // Statistics per value of group_by, or of the single grid key when optimising.
    const std::string gkey = !st.group_by.empty() ? st.group_by
                             : (!st.optimize.empty() && st.grid_axes.size() == 1) ? st.grid_axes[0].front().key
                                                                                    : "";
    for (std::size_t i = 0; i < plan.size(); ++i) {
      if (plan[i].study != s || !results[i].done || !results[i].error.empty()) continue;
      xr.push_back(results[i].x_r);
      er.push_back(results[i].E_r);
      device = results[i].device;
      for (const KeyValue& v : plan[i].values)
        if (v.key == gkey) {
          groups[v.number].first.push_back(results[i].x_r);
          groups[v.number].second.push_back(results[i].E_r);
          group_labels[v.number] = v.label();
        }
    }
    json js = {{"name", st.name}, {"scene", st.scene_path}, {"device", device}, {"runs", xr.size()},
               {"x_r", stats(xr)}, {"E_r", stats(er)}};
    if (!groups.empty()) {
      json jg = json::array();
      double best_value = 0, best = -1e300;
      for (auto& [value, g] : groups) {
        const json sx = stats(g.first), se = stats(g.second);
        jg.push_back({{"value", value}, {"x_r", sx}, {"E_r", se}});
        const double m = (st.optimize == "E_r" ? se : sx)["mean"].get<double>();
        if (m > best) { best = m; best_value = value; }
      }
      js["group_by"] = gkey;
      js["groups"] = jg;
      if (!st.optimize.empty()) js["best"] = {{"key", gkey}, {"value", best_value}, {st.optimize, best}};
    }
    studies.push_back(js);
  }
  const json summary = {{"spec", spec.path},  {"runs", plan.size()},  {"done", done},
                        {"failed", failed},   {"complete", done == plan.size()},
                        {"wall_time_s", wall_s}, {"runs_per_s", wall_s > 0 ? done / wall_s : 0.0},
                        {"studies", studies}};
  std::ofstream(fs::path(out_dir) / "summary.json") << summary.dump(2) << '\n';
  return summary;
}

}  // namespace vines::host
