#include "sim_host/bench/bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/reference/truth.hpp"
#include "sim_host/run/drive.hpp"
#include "sim_host/run/run.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double rel(double a, double b) { return b != 0.0 ? std::fabs(a - b) / std::fabs(b) : kNaN; }

RunTotals run_once(Engine& eng, const Excitation& ex) {
  hal::RecordSource src(ex.samples, ex.rate_hz);
  drive(eng, src);
  return eng.totals();
}

// Runs `run` (which returns its wall time) until the line has been timed for
// min_time_s and min_runs (at most max_runs), then sets the line's runs,
// median and minimum.
template <typename Run>
void time_line(const BenchOptions& opt, std::size_t max_runs, Run run, BenchLine* l) {
  std::vector<double> walls;
  double total = 0;
  while ((total < opt.min_time_s || static_cast<int>(walls.size()) < opt.min_runs) && walls.size() < max_runs) {
    walls.push_back(run());
    total += walls.back();
  }
  std::sort(walls.begin(), walls.end());
  l->runs = static_cast<int>(walls.size());
  l->wall_median_s = walls[walls.size() / 2];
  l->wall_min_s = walls.front();
}

// A line's errors against the truth (NaN where it is not known).
void set_errors(const Truth& truth, BenchLine* l) {
  l->peak_rel_error = truth.known ? rel(l->peak_top, truth.peak_top) : kNaN;
  l->elastic_energy_rel_error = truth.known ? rel(l->elastic_energy, truth.elastic_energy) : kNaN;
  l->x_r_abs_error = truth.known && truth.has_x_r ? std::fabs(l->x_r - truth.x_r) : kNaN;
}

// One firmware line: the scene at one setting.
BenchLine firmware_line(const Scene& base, const FirmwareSetting& set, const Truth& truth, const BenchOptions& opt) {
  const Scene scene = with_setting(base, set, opt);
  const Scalar scalar = set.scalar;
  const double rate = set.rate_hz, rtol = set.rtol;
  const ContactScheme cs = set.scheme;
  const int budget = set.budget;
  const Excitation ex = load_excitation(scene, "");

  BenchLine l;
  l.scene = scene.name;
  l.method = "firmware";
  l.scalar = scalar_name(scalar);
  l.rate_hz = rate;
  l.rtol = rtol;
  l.scheme = scheme_name(cs);
  l.budget = cs == ContactScheme::kAdaptive ? 0 : budget;
  const auto b0 = std::chrono::steady_clock::now();
  refuse_damage(scene, "vines bench");
  std::unique_ptr<Engine> eng = build_engine(scene.params, scalar, scene.path);
  l.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - b0).count();

  // Timed runs: median wall time of whole runs (init + every step).
  RunTotals t;
  time_line(opt, 10000, [&] {
    const auto t0 = std::chrono::steady_clock::now();
    t = run_once(*eng, ex);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }, &l);
  l.steps = t.count.steps;
  l.substeps = t.count.substeps;
  l.rejected = t.count.rejected;
  l.max_substeps_in_step = t.count.max_substeps_in_step;
  l.peak_top = t.peak_top;
  l.elastic_energy = t.elastic_energy;
  l.contacts = static_cast<int>(t.count.contacts);
  l.x_r = kNaN;
  if (scene.params.device.kind != DeviceKind::kNone) {
    SceneParams pb = scene.params;
    pb.device.kind = DeviceKind::kNone;
    const RunTotals b = run_once(*build_engine(pb, scalar, scene.path), ex);
    l.x_r = reduction(b.peak_top, t.peak_top);
  }
  set_errors(truth, &l);
  return l;
}


// One baseline line (DOP853 in double or CVODE) on the record's own points.
BenchLine baseline_line(const Scene& base, const std::string& method, double rtol, const Truth& truth,
                        const BenchOptions& opt) {
  Scene scene = base;
  const hal::Record rec = load_excitation(scene, "").record;
  scene.params.loop.sensor_rate_hz = 1.0 / rec.dt_s;
  const Excitation ex = load_excitation(scene, "");
  BenchLine l;
  l.scene = scene.name;
  l.method = method;
  l.scalar = "double";
  l.rate_hz = ex.rate_hz;
  l.rtol = rtol;
  reference::Options o;
  o.rtol = rtol;
  reference::Result r;
  time_line(opt, 1000, [&] {
    r = reference::integrate(scene.params, ex.samples, ex.rate_hz, baseline_method(method), o);
    return r.wall_s;
  }, &l);
  l.steps = r.steps;
  l.rejected = r.rejected;
  l.peak_top = r.peak_top;
  l.elastic_energy = r.elastic_energy;
  l.contacts = r.contacts;
  l.x_r = truth.has_x_r ? reduction(truth.bare_peak_top, r.peak_top) : kNaN;
  set_errors(truth, &l);
  return l;
}

}  // namespace

const char* const kBaselineMethods[4] = {"dop853", "dop853-driver", "cvode-adams", "cvode-bdf"};

reference::Method baseline_method(const std::string& name) {
  if (name == "dop853") return reference::Method::kDop853;
  if (name == "dop853-driver") return reference::Method::kDop853Driver;
  if (name == "cvode-adams") return reference::Method::kCvodeAdams;
  if (name == "cvode-bdf") return reference::Method::kCvodeBdf;
  throw std::runtime_error("--baseline-methods: unknown method '" + name +
                           "' (dop853, dop853-driver, cvode-adams, cvode-bdf)");
}

const char* scheme_name(ContactScheme s) {
  switch (s) {
    case ContactScheme::kBounded: return "bounded";
    case ContactScheme::kSplit: return "split";
    default: return "adaptive";
  }
}

Truth load_truth(const Scene& scene, const std::string& reference_dir) {
  const fs::path dir = reference_dir.empty() ? fs::path(VINES_SOURCE_DIR) / "data" / "reference" : fs::path(reference_dir);
  const fs::path file = dir / (safe_file_name(scene.name) + ".json");  // as vines reference names it
  Truth t;
  if (!fs::is_regular_file(file)) return t;
  try {
    const json j = json::parse(std::ifstream(file));
    t.peak_top = j.at("peak_top_displacement_m").get<double>();
    t.elastic_energy = j.at("elastic_energy_Js").get<double>();
    t.contacts = j.at("contacts").get<int>();
    if (j.contains("x_r") && !j["x_r"].is_null()) {
      t.has_x_r = true;
      t.x_r = j["x_r"].get<double>();
      t.E_r = j.at("E_r").get<double>();
      t.bare_peak_top = j.at("bare").at("peak_top_displacement_m").get<double>();
      t.bare_elastic_energy = j.at("bare").at("elastic_energy_Js").get<double>();
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": not a reference file: " + e.what());
  }
  t.known = true;
  t.source = file.string();
  return t;
}

std::vector<FirmwareSetting> firmware_settings(const Scene& scene, const BenchOptions& opt) {
  std::vector<Scalar> scalars;
  for (const std::string& s : opt.scalars.empty() ? std::vector<std::string>{"double", "float"} : opt.scalars) {
    if (s != "double" && s != "float" && s != "fixed")
      throw std::runtime_error("--scalars: unknown scalar '" + s + "' (double, float or fixed)");
    scalars.push_back(s == "float" ? Scalar::kFloat : s == "fixed" ? Scalar::kFixed : Scalar::kDouble);
  }
  const std::vector<double> rates = opt.rates_hz.empty() ? std::vector<double>{scene.params.loop.sensor_rate_hz} : opt.rates_hz;
  // The tolerance only matters when there is a contact law to sub-step.
  const bool contacts = scene.params.device.kind == DeviceKind::kVines;
  const std::vector<double> rtols = opt.rtols.empty() || !contacts ? std::vector<double>{scene.params.loop.contact_rtol} : opt.rtols;
  // Schemes: the adaptive one per tolerance, the bounded one per budget (at
  // the scene's tolerance, which sets the event tolerance).
  const LoopParams& loop = scene.params.loop;
  std::vector<std::string> schemes = opt.schemes;
  if (schemes.empty()) schemes = {scheme_name(loop.contact_scheme)};
  const std::vector<int> budgets = opt.bounded_substeps.empty() ? std::vector<int>{loop.bounded_substeps}
                                                                 : opt.bounded_substeps;
  const std::vector<int> splits = opt.split_steps.empty() ? std::vector<int>{loop.split_steps} : opt.split_steps;
  std::vector<FirmwareSetting> out;
  for (Scalar s : scalars)
    for (double rate : rates)
      for (const std::string& scheme : schemes) {
        if (s == Scalar::kFixed && contacts && scheme != "split") {
          std::fprintf(stderr, "vines bench: no fixed-point line for the %s scheme (fixed point runs the split one)\n",
                       scheme.c_str());
          continue;
        }
        if (scheme == "adaptive") {
          for (double rtol : rtols) out.push_back({s, rate, rtol, ContactScheme::kAdaptive, 0});
        } else if (scheme == "bounded" || scheme == "split") {
          const bool bounded = scheme == "bounded";
          for (int k : bounded ? budgets : splits)
            if (contacts || k == (bounded ? budgets : splits).front())
              out.push_back({s, rate, loop.contact_rtol, bounded ? ContactScheme::kBounded : ContactScheme::kSplit, k});
        } else {
          throw std::runtime_error("--schemes: unknown contact scheme '" + scheme + "' (adaptive, bounded, split)");
        }
      }
  return out;
}

Scene with_setting(const Scene& base, const FirmwareSetting& set, const BenchOptions& opt) {
  Scene scene = base;
  scene.scalar = set.scalar;
  LoopParams& loop = scene.params.loop;
  loop.sensor_rate_hz = set.rate_hz;
  loop.contact_rtol = set.rtol;
  loop.contact_scheme = set.scheme;
  if (set.scheme == ContactScheme::kBounded) loop.bounded_substeps = set.budget;
  if (set.scheme == ContactScheme::kSplit) loop.split_steps = set.budget;
  if (!opt.full_outputs) {
    loop.floor_peaks = false;
    loop.energy_ledger = false;
  }
  return scene;
}

std::vector<BaselineSetting> baseline_settings(const BenchOptions& opt) {
  for (const std::string& m : opt.baseline_methods) baseline_method(m);
  std::vector<BaselineSetting> out;
  for (const char* m : kBaselineMethods) {
    const auto& asked = opt.baseline_methods;
    if (!asked.empty() && std::find(asked.begin(), asked.end(), m) == asked.end()) continue;
    for (double rtol : opt.baseline_rtols) out.push_back({m, rtol});
  }
  return out;
}

std::vector<BenchLine> bench_scene(const Scene& scene, const BenchOptions& opt) {
  const Truth truth = load_truth(scene, opt.reference_dir);
  std::vector<BenchLine> lines;
  for (const FirmwareSetting& set : firmware_settings(scene, opt)) lines.push_back(firmware_line(scene, set, truth, opt));
  // Baselines in table order, whatever the order asked.
  for (const BaselineSetting& b : baseline_settings(opt)) lines.push_back(baseline_line(scene, b.method, b.rtol, truth, opt));
  return lines;
}

json line_json(const BenchLine& l) {
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"scene", l.scene},
          {"method", l.method},
          {"scalar", l.scalar},
          {"sensor_rate_hz", l.rate_hz},
          {"contact_rtol", l.rtol},
          {"contact_scheme", l.scheme},
          {"bounded_substeps", l.method == "firmware" && l.scheme == "bounded" ? json(l.budget) : json(nullptr)},
          {"split_steps", l.method == "firmware" && l.scheme == "split" ? json(l.budget) : json(nullptr)},
          {"max_substeps_in_a_step", l.max_substeps_in_step},
          {"runs", l.runs},
          {"wall_s_median", l.wall_median_s},
          {"wall_s_min", l.wall_min_s},
          {"build_s", l.build_s},
          {"steps", l.steps},
          {"substeps", l.substeps},
          {"rejected_substeps", l.rejected},
          {"peak_top_displacement_m", l.peak_top},
          {"elastic_energy_Js", l.elastic_energy},
          {"x_r", num(l.x_r)},
          {"contacts", l.contacts},
          {"peak_rel_error", num(l.peak_rel_error)},
          {"elastic_energy_rel_error", num(l.elastic_energy_rel_error)},
          {"x_r_abs_error", num(l.x_r_abs_error)}};
}

std::string format_table(const std::vector<BenchLine>& lines) {
  std::string out;
  char buf[320];
  std::snprintf(buf, sizeof buf, "%-26s %-13s %-10s %-6s %8s %7s %10s %5s %8s %8s %7s %9s %9s %9s %8s\n", "scene",
                "method", "scheme", "scalar", "rate_hz", "rtol", "wall_ms", "runs", "steps", "substeps", "max_sub",
                "peak_err", "Ee_err", "x_r_err", "contacts");
  out += buf;
  for (const BenchLine& l : lines) {
    char scheme[32] = "";
    if (l.method == "firmware")
      std::snprintf(scheme, sizeof scheme, l.budget > 0 ? "%s/%d" : "%s", l.scheme.c_str(), l.budget);
    std::snprintf(buf, sizeof buf,
                  "%-26s %-13s %-10s %-6s %8.0f %7.3g %10.4f %5d %8lld %8lld %7lld %9.2e %9.2e %9.2e %8d\n",
                  l.scene.c_str(), l.method.c_str(), scheme, l.scalar.c_str(), l.rate_hz, l.rtol,
                  1e3 * l.wall_median_s, l.runs, l.steps, l.substeps, l.max_substeps_in_step, l.peak_rel_error,
                  l.elastic_energy_rel_error, l.x_r_abs_error, l.contacts);
    out += buf;
  }
  return out;
}

}  // namespace vines::host
