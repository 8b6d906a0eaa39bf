#include "sim_host/run/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/io/csv.hpp"
#include "sim_host/io/npy.hpp"
#include "sim_host/io/digest.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/run/damage.hpp"
#include "sim_host/run/drive.hpp"
#include "sim_host/scene/names.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::vector<double> head(const FloorArray& a, int n) { return {a.begin(), a.begin() + n}; }

// What a run keeps every `every` steps: its snapshots (RunReport::series),
// and the timeseries' values (a device run: its columns; the bare frame's
// beside it: its top floor and E_e), each row `width` doubles.
struct Keep {
  bool snapshots = false;
  int width = 0;  // 0: no values
  bool bare = false;
};

struct Trace {
  RunTotals totals;
  ModelInfo info;                        // the scene's model
  std::optional<ModelInfo> damaged_info;  // with [damage]: the model after it
  std::vector<Snapshot> rows;
  std::vector<double> values;  // rows of Keep::width
  double wall_s = 0;
};

// A snapshot's values in the timeseries' columns (the device's), or the
// bare frame's two.
void append_values(const Snapshot& s, int n, DeviceKind kind, bool bare, std::vector<double>* v) {
  if (bare) {
    v->insert(v->end(), {s.x[n - 1], s.elastic_energy});
    return;
  }
  v->insert(v->end(), {s.t, s.ag});
  for (const FloorArray* a : {&s.x, &s.v, &s.acc, &s.drift}) v->insert(v->end(), a->begin(), a->begin() + n);
  v->push_back(s.elastic_energy);
  if (kind == DeviceKind::kVines)
    v->insert(v->end(), {s.particle_x, s.particle_v, s.wall_left, s.wall_right, s.contact_force,
                         static_cast<double>(s.mode)});
  if (kind == DeviceKind::kTmd) v->insert(v->end(), {s.tmd_x, s.tmd_v});
}

// One engine run over the samples, keeping what `keep` asks every `every` steps.
// With [damage], the damaged model from the sample at damage.time_s on.
Trace run_engine(const Scene& scene, const SceneParams& p, const Excitation& ex, int every, const Keep& keep) {
  DamagedRun eng(p, scene.damage, scene.scalar, ex.rate_hz, scene.path);
  Trace tr;
  tr.info = eng.undamaged().info();
  if (const Engine* after = eng.damaged()) tr.damaged_info = after->info();
  // Every row's room at once: no copies as they grow.
  const std::size_t rows = every > 0 ? ex.samples.size() / static_cast<std::size_t>(every) + 2 : 0;
  if (keep.snapshots) tr.rows.reserve(rows);
  tr.values.reserve(rows * static_cast<std::size_t>(keep.width));
  const int n = tr.info.stories;
  const auto t0 = std::chrono::steady_clock::now();
  hal::RecordSource src(ex.samples, ex.rate_hz);
  drive(eng, src, static_cast<std::size_t>(std::max(every, 0)), [&](std::size_t) {
    const Snapshot s = eng.engine().snapshot();
    if (keep.width > 0) append_values(s, n, p.device.kind, keep.bare, &tr.values);
    if (keep.snapshots) tr.rows.push_back(s);
  });
  tr.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  tr.totals = eng.engine().totals();
  return tr;
}

}  // namespace

json modal_json(const ModelInfo& in) {
  const int n = in.stories;
  json mass_fraction = json::array(), shapes = json::array();
  for (int j = 0; j < n; ++j) {
    mass_fraction.push_back(in.m_eff[j] / in.total_mass);
    shapes.push_back(head(in.mode_shapes[j], n));
  }
  return {{"frequency_hz", head(in.frequency_hz, n)},
          {"damping_ratio", head(in.zeta, n)},
          {"effective_mass_kg", head(in.m_eff, n)},
          {"effective_mass_fraction", mass_fraction},
          {"participation_factor", head(in.gamma, n)},
          {"mode_shapes", shapes},  // phi_j * gamma_j, bottom floor first (Table 1's normalisation)
          {"total_mass_kg", in.total_mass}};
}

namespace {

json response_json(const RunTotals& t, int n) {
  return {{"peak_displacement_m", head(t.peak_x, n)},
          {"peak_drift_m", head(t.peak_drift, n)},
          {"peak_top_displacement_m", t.peak_top},
          {"t_peak_top_s", t.t_peak_top},
          {"elastic_energy_integral", t.elastic_energy},
          {"strain_energy_positive_increments", t.strain_increments}};
}

// The device's design as the model built it.
json device_json(DeviceKind kind, const ModelInfo& info) {
  json dp = {{"floor", info.device_floor}};
  if (kind == DeviceKind::kTmd) {
    const TmdDesign& d = info.tmd;
    dp.update({{"mass_kg", d.mass}, {"k_n_per_m", d.k}, {"c_ns_per_m", d.c}, {"mu", d.mu},
               {"lambda", d.lambda}, {"xi", d.xi}, {"frequency_hz", d.omega / (2 * M_PI)}});
  }
  if (kind == DeviceKind::kVines) {
    const VinesDesign& d = info.vines;
    dp.update({{"mass_kg", d.mass}, {"R_m", d.radius}, {"b_m", d.box_length}, {"gap_m", d.gap},
               {"beta", d.box_length / (2 * d.radius)}, {"hertz_C", d.c}, {"eps", d.eps},
               {"tau_s", d.tau}, {"v_ref_mps", d.v_ref}, {"reduced_mass_kg", d.m_star}});
  }
  return dp;
}

// The timeseries' columns: time, ground, per-floor quantities, E_e, the
// device's state, the bare frame's; contact_mode is an integer.
std::vector<NpyField> timeseries_columns(const Scene& scene, int n, bool bare) {
  std::vector<NpyField> c{{"t_s"}, {"ag_mps2"}};
  for (const char* q : {"x", "v", "acc", "drift"})
    for (int i = 1; i <= n; ++i)
      c.push_back({q + std::to_string(i) + (q[0] == 'x' || q[0] == 'd' ? "_m" : q[0] == 'v' ? "_mps" : "_mps2")});
  c.push_back({"Ee_Js"});
  const DeviceKind kind = scene.params.device.kind;
  if (kind == DeviceKind::kVines) {
    for (const char* h : {"particle_x_m", "particle_v_mps", "wall_left_m", "wall_right_m", "contact_force_n"})
      c.push_back({h});
    c.push_back({"contact_mode", true});
  }
  if (kind == DeviceKind::kTmd) c.insert(c.end(), {{"tmd_x_m"}, {"tmd_v_mps"}});
  if (bare) c.insert(c.end(), {{"bare_x_top_m"}, {"bare_Ee_Js"}});
  return c;
}

// timeseries.csv (every number in its shortest exact form) or
// timeseries.npy: the same columns, values bit for bit either way. A row is
// the device run's values, then the bare frame's.
void write_timeseries(const fs::path& file, const Scene& scene, const Trace& dev, const Trace* bare) {
  const std::vector<NpyField> cols = timeseries_columns(scene, dev.info.stories, bare != nullptr);
  const std::size_t width = cols.size() - (bare ? 2 : 0), rows = dev.values.size() / width;
  std::vector<double> v(cols.size());
  auto row = [&](std::size_t r) {
    std::copy_n(dev.values.begin() + static_cast<std::ptrdiff_t>(r * width), width, v.begin());
    if (bare) std::copy_n(bare->values.begin() + static_cast<std::ptrdiff_t>(2 * r), 2, v.begin() + width);
  };
  if (scene.output.format == TimeseriesFormat::kNpy) {
    NpyWriter npy(file.string(), cols, rows);
    for (std::size_t r = 0; r < rows; ++r) {
      row(r);
      npy.row(v.data());
    }
    npy.close();
    return;
  }
  CsvWriter csv(file.string());
  for (const NpyField& c : cols) csv.raw(c.name);
  csv.end_row();
  for (std::size_t r = 0; r < rows; ++r) {
    row(r);
    for (std::size_t i = 0; i < cols.size(); ++i)
      cols[i].integer ? csv.integer(std::llround(v[i])) : csv.exact(v[i]);
    csv.end_row();
  }
  csv.close();
}

// The scene's pga_g, the resampling to the sensor rate and duration_s, on a
// loaded record (its scale already applied).
Excitation finish_excitation(const Scene& scene, Excitation ex) {
  const std::string& path = ex.record.path;
  if (scene.target_pga_mps2 > 0.0) {
    const double pga = ex.record.pga_mps2();
    if (!(pga > 0.0)) throw std::runtime_error(path + ": all samples are zero, cannot scale to pga_g");
    for (double& a : ex.record.accel_mps2) a *= scene.target_pga_mps2 / pga;
  }
  ex.rate_hz = scene.params.loop.sensor_rate_hz;
  ex.samples = hal::resample(ex.record, ex.rate_hz);
  if (scene.duration_s > 0.0) {
    const auto keep = static_cast<std::size_t>(std::llround(scene.duration_s * ex.rate_hz)) + 1;
    if (keep < ex.samples.size()) ex.samples.resize(keep);
  }
  if (ex.samples.size() < 2)
    throw std::runtime_error(path + ": record too short for one step at the sensor rate");
  return ex;
}

}  // namespace

Excitation load_excitation(const Scene& scene, const std::string& record_override,
                           const RecordReading& reading) {
  hal::RecordSpec spec = scene.record;
  if (!record_override.empty()) {
    // The file's own format (detected unless forced), units, column and dt;
    // the scene's scale / pga_g and duration_s still apply.
    spec.path = record_override;
    spec.format = reading.format;
    spec.units = reading.units;
    spec.column = reading.column;
    spec.dt_s = reading.dt_s;
    const bool values_only = spec.format == hal::RecordFormat::kAccel ||
                             (spec.format == hal::RecordFormat::kAuto &&
                              hal::detect_record_format(spec.path) == hal::RecordFormat::kAccel);
    if (values_only && !(spec.dt_s > 0.0))
      throw hal::RecordError("--record " + spec.path +
                             ": one column of values and no time: give its sample step with --record-dt "
                             "SECONDS (or --record-format for another format)");
  } else {
    spec.path = resolve_record_path(spec.path, scene.path);
  }
  Excitation ex;
  ex.record = hal::load_record(spec);
  return finish_excitation(scene, std::move(ex));
}

Excitation excitation_from_record(const Scene& scene, hal::Record record) {
  hal::check_record(record);
  for (double& a : record.accel_mps2) a *= scene.record.scale;
  Excitation ex;
  ex.record = std::move(record);
  return finish_excitation(scene, std::move(ex));
}

RunReport run_scene(const Scene& scene, const RunOptions& opt) {
  return run_scene(scene, load_excitation(scene, opt.record_override, opt.record_reading), opt);
}

RunReport run_scene(const Scene& scene, const Excitation& ex, const RunOptions& opt) {
  const SceneParams& p = scene.params;
  const bool has_device = p.device.kind != DeviceKind::kNone;
  const bool series = !opt.out_dir.empty() && scene.output.timeseries;
  const int every = series || opt.keep_series
                        ? static_cast<int>(std::llround(p.loop.sensor_rate_hz / scene.output.rate_hz))
                        : 0;

  // A [damage] the run cannot take (after the record's end, in fixed point):
  // refused before anything is written, not ignored.
  check_damage_time(scene, static_cast<double>(ex.samples.size() - 1) / ex.rate_hz);
  check_damage_scalar(scene.damage, scene.scalar, scene.path);

  // The run's folder, claimed (and locked) before the run: its marker keeps
  // what the results come from, the scene's and the record's bytes.
  std::optional<OutputDir> out;
  if (!opt.out_dir.empty()) {
    Digest d;
    d.add(scene.path);
    d.add_file(scene.path);
    d.add_file(ex.record.path);
    out.emplace(opt.out_dir, "vines run", std::vector<std::string>{"summary.json", "timeseries.csv", "timeseries.npy"},
                d.hex());
  }

  // The device run, and with a device the bare frame on the same samples.
  const int width = series ? static_cast<int>(timeseries_columns(scene, p.frame.stories, false).size()) : 0;
  const Trace dev = run_engine(scene, p, ex, every, Keep{opt.keep_series, width, false});
  Trace bare;
  if (has_device) {
    SceneParams pb = p;
    pb.device.kind = DeviceKind::kNone;
    bare = run_engine(scene, pb, ex, every, Keep{opt.keep_series, series ? 2 : 0, true});
  }
  RunReport r;
  r.scene = scene.name;
  r.scene_file = scene.path;
  r.params = p;
  r.scalar = scene.scalar;
  r.record = {ex.record.path, ex.record.dt_s, ex.record.accel_mps2.size(), ex.record.pga_mps2(),
              static_cast<double>(ex.samples.size() - 1) / ex.rate_hz};
  r.info = dev.info;
  r.damage = scene.damage;
  r.damage_switch_s = static_cast<double>(damage_sample(scene.damage.time_s, ex.rate_hz)) / ex.rate_hz;
  r.damaged_info = dev.damaged_info;
  r.totals = dev.totals;
  if (has_device) r.bare = bare.totals;
  r.wall_s = dev.wall_s;
  r.status = device_status(r.totals, r.bare ? &*r.bare : nullptr, p, r.info, r.scalar);

  // The run's folder: the timeseries, then summary.json (the file that says the
  // run is complete) last; a timeseries of an earlier run is removed.
  if (out) {
    std::vector<std::string> written{"summary.json"};
    if (series) {
      const char* name = scene.output.format == TimeseriesFormat::kNpy ? "timeseries.npy" : "timeseries.csv";
      write_timeseries(out->file(name), scene, dev, has_device ? &bare : nullptr);
      written.push_back(name);
    }
    write_file_atomic(out->file("summary.json"), r.to_json().dump(2) + '\n');
    out->finish(written);
  }
  if (opt.keep_series) {
    r.series = dev.rows;
    if (has_device) r.bare_series = bare.rows;
  }
  return r;
}

json RunReport::to_json() const {
  const SceneParams& p = params;
  const RunTotals& t = totals;
  json j;
  j["scene"] = scene;
  j["scene_file"] = scene_file;
  j["device"] = device_name(p.device.kind);
  if (p.device.kind == DeviceKind::kVines) j["contact_law"] = law_name(p.device.vines.law);
  j["stories"] = info.stories;
  j["scalar"] = scalar_name(scalar);
  j["sensor_rate_hz"] = p.loop.sensor_rate_hz;
  j["record"] = {{"path", record.path},
                 {"dt_s", record.dt_s},
                 {"points", record.points},
                 {"pga_mps2", record.pga_mps2},
                 {"simulated_s", record.simulated_s}};
  j.update(response_json(t, info.stories));
  if (bare) {
    const RunTotals& b = *bare;
    j["x_r"] = x_r();
    j["E_r"] = E_r();
    j["E_r_positive_increments"] = reduction(b.strain_increments, t.strain_increments);
    j["bare"] = response_json(b, info.stories);
  }
  j["contacts"] = t.count.contacts;
  if (scalar == Scalar::kFixed) {
    j["fixed_saturations"] = t.fixed_saturations;
    j["fixed_scales"] = {{"accel_mps2", p.fixed.accel_mps2},
                         {"amplification", p.fixed.amplification},
                         {"contact_speed_mps", p.fixed.contact_speed_mps}};
  }
  if (p.device.kind == DeviceKind::kVines) j["max_overlap_m"] = t.max_overlap;
  if (p.loop.energy_ledger) {
    const Ledger& l = t.ledger;
    j["energy_balance_residual"] = l.relative_residual();
    j["energy_J"] = {{"input", l.input},     {"frame_damping", l.damping}, {"contact_dissipation", l.contact},
                     {"kinetic", l.kinetic}, {"frame_strain", l.strain},   {"device_stored", l.device},
                     {"residual", l.residual}};
  } else {
    j["energy_balance_residual"] = nullptr;
    j["energy_balance"] = "not computed (loop.energy_ledger = false)";
  }
  j["counters"] = {{"steps", t.count.steps},
                   {"substep_steps", t.count.careful_steps},
                   {"substeps", t.count.substeps},
                   {"contact_substeps", t.count.contact_substeps},
                   {"rejected_substeps", t.count.rejected},
                   {"events", t.count.events},
                   {"substep_cap_hits", t.count.cap_hits},
                   {"max_substeps_in_a_step", t.count.max_substeps_in_step},
                   {"max_events_in_a_step", t.count.max_events_in_step},
                   {"bad_samples_held", t.count.bad_samples},
                   {"divergences_rolled_back", t.count.divergences}};
  j["modal"] = modal_json(info);
  // The damage that struck during the run (both runs, device and bare).
  if (damage.present()) {
    j["damage"] = {{"time_s", damage.time_s},
                   {"switch_s", damage_switch_s},
                   {"stiffness_scales", damage.stiffness_scales},
                   {"frequency_hz_after", damaged_info ? head(damaged_info->frequency_hz, info.stories)
                                                       : head(info.frequency_hz, info.stories)}};
  } else {
    j["damage"] = nullptr;
  }
  if (bare) j["device_params"] = device_json(p.device.kind, info);
  j["wall_time_s"] = wall_s;
  // Whether the figures above can be trusted (docs/model.md, "Run status").
  j["status"] = status.name();
  j["degraded_reasons"] = status.reasons_json();
  return j;
}

}  // namespace vines::host
