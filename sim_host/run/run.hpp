// `vines run`: one scene on one record, with the bare frame alongside when the
// scene has a device; writes DIR/summary.json and DIR/timeseries.csv (or .npy).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/engines/engine.hpp"
#include "sim_host/run/status.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {

// How to read a --record file. The scene's [record] describes the scene's own
// file: for another file only its intensity and window (scale or pga_g,
// duration_s) still apply; the format, units, column and dt are the file's.
struct RecordReading {
  hal::RecordFormat format = hal::RecordFormat::kAuto;  // --record-format (auto: from the file)
  hal::Units units = hal::Units::kG;  // --record-units (an AT2 file's header wins)
  int column = 1;                     // --record-column: time-accel, 1 = first after time
  double dt_s = 0.0;                  // --record-dt: a single column of values
};

struct RunOptions {
  std::string record_override;  // --record PATH
  RecordReading record_reading;  // how to read it
  std::string out_dir;          // --out DIR ("" = write nothing)
  bool quiet = false;
  bool keep_series = false;     // the time series (output rate) in RunReport::series (Python)
};

// The record of a scene, loaded, scaled and resampled to the sensor rate.
struct Excitation {
  hal::Record record;
  std::vector<double> samples;  // at the sensor rate, sample k at t = k / rate
  double rate_hz = 0;
};

// How much a device reduces a figure of the bare frame: x_r from the peak top
// displacements, E_r from the elastic energy integrals (docs/model.md).
inline double reduction(double bare, double with_device) { return (bare - with_device) / bare; }

// The scene's record, or record_override ("" = none) read as `reading` says.
Excitation load_excitation(const Scene& scene, const std::string& record_override,
                           const RecordReading& reading = {});

// The excitation of a record already in memory (m/s^2, checked as a file's
// would be: hal::check_record), as the scene runs it: its scale or pga_g,
// resampled to the sensor rate, cut to duration_s.
Excitation excitation_from_record(const Scene& scene, hal::Record record);

// The record a run read, as loaded and scaled.
struct RecordSummary {
  std::string path;
  double dt_s = 0;
  std::size_t points = 0;
  double pga_mps2 = 0;
  double simulated_s = 0;  // the samples run, at the sensor rate
};

// What `vines run` reports (summary.json is to_json()).
struct RunReport {
  std::string scene, scene_file;
  SceneParams params;
  Scalar scalar = Scalar::kDouble;
  RecordSummary record;
  ModelInfo info;                 // the model of the device run
  RunTotals totals;               // the device run
  std::optional<RunTotals> bare;  // with a device: the bare frame on the same record
  double wall_s = 0;              // the device run's loop
  RunStatus status;               // ok, or degraded and why (either run)
  // The scene's [damage] (both runs switch to the damaged frame at the
  // sample switch_s, the first at or after damage.time_s), and the damaged
  // model's modes (none when no factor differs from 1).
  DamageSpec damage;
  double damage_switch_s = 0;
  std::optional<ModelInfo> damaged_info;
  // With RunOptions::keep_series: the steps at the output rate (t = 0 first),
  // of the device run and (with a device) the bare frame.
  std::vector<Snapshot> series, bare_series;
  double x_r() const { return reduction(bare->peak_top, totals.peak_top); }
  double E_r() const { return reduction(bare->elastic_energy, totals.elastic_energy); }
  nlohmann::json to_json() const;
};

// Runs the scene's device (and the bare frame if there is a device), returns
// the report (summary.json and timeseries.csv are written to out_dir when
// given). Throws std::runtime_error with a message naming the input on any
// user error.
RunReport run_scene(const Scene& scene, const RunOptions& opt);
// The same on an excitation already loaded (opt.record_override unused).
RunReport run_scene(const Scene& scene, const Excitation& ex, const RunOptions& opt);

// The modal report of summary.json ("modal"): frequencies, damping ratios,
// participation, effective masses, mode shapes.
nlohmann::json modal_json(const ModelInfo& info);

}  // namespace vines::host
