#include "sim_host/bench/ensemble.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/reference/truth.hpp"
#include "sim_host/run/drive.hpp"
#include "sim_host/studies/parallel.hpp"
#include "vines/model/contact_laws.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The initial-condition grid of data/studies/initial_conditions.toml: 33 x
// 33 points in [-1, 1]^2. Member m takes point (577 m + 544) mod 1089: the
// grid's centre first, then strides that visit every row and column.
constexpr int kGridSide = 33, kGridPoints = kGridSide * kGridSide, kGridStride = 577;

double grid_value(int i) { return -1.0 + 2.0 * i / (kGridSide - 1); }

std::string ic_label(double u, double w) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "ic u=%+.4f w=%+.4f", u, w);
  return buf;
}

// The AT2 records beside the scene's record, by name.
std::vector<fs::path> records_beside(const Scene& scene) {
  const fs::path dir = fs::path(resolve_record_path(scene.record.path, scene.path)).parent_path();
  std::vector<fs::path> out;
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".at2") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// One member's truth at one rate: the device run and the bare frame's.
struct MemberTruth {
  Excitation ex;
  SceneParams params;  // as the lines run it (law calibration kept)
  reference::Result device, bare;
};

EnsembleStat stat_of(std::vector<double> v) {
  EnsembleStat s;
  if (v.empty()) return s;
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  std::sort(v.begin(), v.end());
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(v.size())));
  s.p90 = v[std::max<std::size_t>(rank, 1) - 1];
  return s;
}

// What one run gave, to be set against its member's truth.
struct Outcome {
  double peak = 0, elastic_energy = 0;
  int contacts = 0;
  bool failed = false;  // the method gave up on this member (its message on stderr)
};

// The line's statistics over the members it ran (a failed one is counted apart).
void score(const std::vector<MemberTruth>& truth, const std::vector<Outcome>& out, EnsembleLine* l) {
  std::vector<double> peak, x_r, E_r;
  int same = 0;
  double diff = 0;
  for (std::size_t m = 0; m < truth.size(); ++m) {
    const MemberTruth& t = truth[m];
    if (out[m].failed) {
      ++l->failed;
      continue;
    }
    peak.push_back(std::fabs(out[m].peak - t.device.peak_top) / t.device.peak_top);
    x_r.push_back(std::fabs(out[m].peak - t.device.peak_top) / t.bare.peak_top);
    E_r.push_back(std::fabs(out[m].elastic_energy - t.device.elastic_energy) / t.bare.elastic_energy);
    same += out[m].contacts == t.device.contacts;
    diff += std::abs(out[m].contacts - t.device.contacts);
  }
  const double n = static_cast<double>(peak.size());
  l->members = static_cast<int>(truth.size());
  if (peak.empty()) return;  // failed on every member: no figures
  l->peak = stat_of(peak);
  l->x_r = stat_of(x_r);
  l->E_r = stat_of(E_r);
  l->contacts_same = same / n;
  l->contacts_diff = diff / n;
}

// Runs run(m) for every member, in passes over all of them until opt's
// minimum time (one pass at least); returns the mean wall time of a run.
// A run that returns 0 (failed) is not counted.
template <typename Run>
double time_members(std::size_t members, const BenchOptions& opt, Run run) {
  double total = 0;
  std::size_t runs = 0;
  do {
    for (std::size_t m = 0; m < members; ++m) {
      const double wall = run(m);
      total += wall;
      runs += wall > 0;
    }
  } while (runs > 0 && total < opt.min_time_s);
  return runs > 0 ? total / static_cast<double>(runs) : 0.0;
}

EnsembleLine firmware_line(const std::vector<EnsembleMember>& members, const std::vector<MemberTruth>& truth,
                           const FirmwareSetting& set, const BenchOptions& opt) {
  EnsembleLine l;
  BenchLine& b = l.setting;
  b.scene = members[0].scene.name;
  b.method = "firmware";
  b.scalar = scalar_name(set.scalar);
  b.rate_hz = set.rate_hz;
  b.rtol = set.rtol;
  b.scheme = scheme_name(set.scheme);
  b.budget = set.budget;
  // Models built before the clock starts, as in the single-scene lines.
  std::vector<std::unique_ptr<Engine>> engines;
  for (std::size_t m = 0; m < members.size(); ++m) {
    const Scene s = with_setting(members[m].scene, set, opt);
    engines.push_back(build_engine(s.params, set.scalar, s.path));
  }
  std::vector<Outcome> out(members.size());
  l.run_s = time_members(members.size(), opt, [&](std::size_t m) {
    hal::RecordSource src(truth[m].ex.samples, truth[m].ex.rate_hz);
    const auto t0 = Clock::now();
    drive(*engines[m], src);
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    const RunTotals t = engines[m]->totals();
    out[m] = {t.peak_top, t.elastic_energy, static_cast<int>(t.count.contacts)};
    return wall;
  });
  score(truth, out, &l);
  return l;
}

EnsembleLine baseline_line(const std::vector<EnsembleMember>& members, const std::vector<MemberTruth>& truth,
                           const BaselineSetting& set, double rate, const BenchOptions& opt) {
  EnsembleLine l;
  BenchLine& b = l.setting;
  b.scene = members[0].scene.name;
  b.method = set.method;
  b.scalar = "double";
  b.rate_hz = rate;
  b.rtol = set.rtol;
  std::vector<Outcome> out(members.size());
  reference::Options o;
  o.rtol = set.rtol;
  // A member the method fails on (CVODE's root finding can give up) is
  // reported once, counted, and not run again in the later timing passes:
  // the line's figures are over the rest.
  l.run_s = time_members(members.size(), opt, [&](std::size_t m) {
    if (out[m].failed) return 0.0;
    const MemberTruth& t = truth[m];
    try {
      const reference::Result r =
          reference::integrate(t.params, t.ex.samples, t.ex.rate_hz, baseline_method(set.method), o);
      out[m] = {r.peak_top, r.elastic_energy, r.contacts, false};
      return r.wall_s;
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "vines bench: %s at rtol %g failed on member %s: %s\n", set.method.c_str(), set.rtol,
                   members[m].label.c_str(), e.what());
      out[m].failed = true;
      return 0.0;
    }
  });
  score(truth, out, &l);
  return l;
}

// Every member's input at `rate` and its converged references.
std::vector<MemberTruth> truths_at(const std::vector<EnsembleMember>& members, double rate, const BenchOptions& opt) {
  std::vector<MemberTruth> out(members.size());
  MapOptions mo;
  mo.threads = opt.threads;
  mo.progress = true;
  mo.label = "bench references";
  mo.unit = "members";
  parallel_map(members.size(), mo, [&](std::size_t m) {
    Scene s = members[m].scene;
    s.params.loop.sensor_rate_hz = rate;
    MemberTruth& t = out[m];
    t.ex = load_excitation(s, "");
    t.params = s.params;
    t.device = reference::integrate(t.params, t.ex.samples, t.ex.rate_hz, reference::Method::kReference, {});
    SceneParams bare = t.params;
    bare.device.kind = DeviceKind::kNone;
    t.bare = reference::integrate(bare, t.ex.samples, t.ex.rate_hz, reference::Method::kReference, {});
  });
  return out;
}

}  // namespace

std::vector<EnsembleMember> ensemble_members(const Scene& scene, int n) {
  if (scene.params.device.kind != DeviceKind::kVines)
    throw std::runtime_error("--ensemble: " + scene.path + " has no VI NES (the ensemble varies the sphere and the record)");
  if (n < 2) throw std::runtime_error("--ensemble: needs 2 members or more, got " + std::to_string(n));
  // The scene's design (free travel, law calibration) and its bare frame's peak top-floor speed.
  refuse_damage(scene, "vines bench --ensemble");
  const std::unique_ptr<Engine> eng = build_engine(scene.params, Scalar::kDouble, scene.path);
  const VinesDesign design = eng->info().vines;
  const Excitation ex = load_excitation(scene, "");
  SceneParams bare = scene.params;
  bare.device.kind = DeviceKind::kNone;
  const std::unique_ptr<Engine> bare_eng = build_engine(bare, Scalar::kDouble, scene.path);
  hal::RecordSource src(ex.samples, ex.rate_hz);
  drive(*bare_eng, src);
  const double vmax = bare_eng->totals().peak_top_velocity;
  double pga = 0;
  for (double a : ex.record.accel_mps2) pga = std::max(pga, std::fabs(a));

  std::vector<EnsembleMember> out;
  const std::vector<fs::path> records = records_beside(scene);
  const std::size_t n_rec = std::min(records.size(), static_cast<std::size_t>(n / 2));
  for (std::size_t r = 0; r < n_rec; ++r) {
    EnsembleMember m{records[r].filename().string(), scene};
    m.scene.record = hal::RecordSpec{};
    m.scene.record.path = records[r].string();
    m.scene.record.format = hal::RecordFormat::kAt2;
    m.scene.target_pga_mps2 = pga;
    out.push_back(std::move(m));
  }
  for (int k = 0; static_cast<int>(out.size()) < n; ++k) {
    const int point = (kGridStride * k + kGridPoints / 2) % kGridPoints;
    const double u = grid_value(point / kGridSide), w = grid_value(point % kGridSide);
    EnsembleMember m{ic_label(u, w), scene};
    VinesParams& v = m.scene.params.device.vines;
    v.initial_position_m = u * design.gap;
    v.start_at_left_wall = false;
    v.initial_velocity_mps = w * vmax;
    law_keep(design, &v);
    out.push_back(std::move(m));
  }
  return out;
}

std::vector<EnsembleLine> bench_ensemble(const Scene& scene, const BenchOptions& opt, int n) {
  const std::vector<EnsembleMember> members = ensemble_members(scene, n);
  const std::vector<FirmwareSetting> firmware = firmware_settings(scene, opt);
  const std::vector<BaselineSetting> baselines = baseline_settings(opt);
  std::vector<double> rates;
  for (const FirmwareSetting& f : firmware)
    if (std::find(rates.begin(), rates.end(), f.rate_hz) == rates.end()) rates.push_back(f.rate_hz);
  std::vector<EnsembleLine> lines;
  // Every line of a rate reads the members' input at that rate, the
  // baselines included (on the record's own points when it is the record's rate).
  for (double rate : rates) {
    const std::vector<MemberTruth> truth = truths_at(members, rate, opt);
    for (const FirmwareSetting& f : firmware)
      if (f.rate_hz == rate) lines.push_back(firmware_line(members, truth, f, opt));
    for (const BaselineSetting& b : baselines) lines.push_back(baseline_line(members, truth, b, rate, opt));
  }
  return lines;
}

nlohmann::json ensemble_line_json(const EnsembleLine& l) {
  nlohmann::json j = line_json(l.setting);
  for (const char* k : {"runs", "wall_s_median", "wall_s_min", "build_s", "steps", "substeps", "rejected_substeps",
                        "max_substeps_in_a_step", "peak_top_displacement_m", "elastic_energy_Js", "x_r", "contacts",
                        "peak_rel_error", "elastic_energy_rel_error", "x_r_abs_error"})
    j.erase(k);
  auto stat = [](const EnsembleStat& s) { return nlohmann::json{{"mean", s.mean}, {"p90", s.p90}}; };
  j["members"] = l.members;
  j["run_s_mean"] = l.run_s;
  j["peak_rel_error"] = stat(l.peak);
  j["x_r_abs_error"] = stat(l.x_r);
  j["E_r_abs_error"] = stat(l.E_r);
  j["contacts_same_share"] = l.contacts_same;
  j["contacts_abs_diff_mean"] = l.contacts_diff;
  j["failed_members"] = l.failed;
  return j;
}

std::string format_ensemble_table(const std::vector<EnsembleLine>& lines) {
  std::string out;
  char buf[320];
  std::snprintf(buf, sizeof buf, "%-13s %-10s %-6s %7s %7s %8s %9s %9s %9s %9s %9s %9s %6s %6s %6s\n", "method",
                "scheme", "scalar", "rate_hz", "rtol", "run_ms", "peak_mean", "peak_p90", "x_r_mean", "x_r_p90",
                "E_r_mean", "E_r_p90", "c_same", "c_diff", "failed");
  out += buf;
  for (const EnsembleLine& l : lines) {
    const BenchLine& b = l.setting;
    char scheme[32] = "";
    if (b.method == "firmware") std::snprintf(scheme, sizeof scheme, b.budget > 0 ? "%s/%d" : "%s", b.scheme.c_str(), b.budget);
    std::snprintf(buf, sizeof buf,
                  "%-13s %-10s %-6s %7.0f %7.3g %8.4f %9.2e %9.2e %9.2e %9.2e %9.2e %9.2e %5.0f%% %6.2f %6d\n",
                  b.method.c_str(), scheme, b.scalar.c_str(), b.rate_hz, b.rtol, 1e3 * l.run_s, l.peak.mean, l.peak.p90,
                  l.x_r.mean, l.x_r.p90, l.E_r.mean, l.E_r.p90, 100 * l.contacts_same, l.contacts_diff, l.failed);
    out += buf;
  }
  return out;
}

}  // namespace vines::host
