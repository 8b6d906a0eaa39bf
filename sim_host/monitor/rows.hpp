// The page's series for a run: names (those of the run's --csv columns, so
// that `vines view` and the browser test read them back by name), units and
// the chart each is drawn in; and, for a bench run, their values sample by
// sample from the record.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/hil/bench.hpp"
#include "sim_host/hil/record.hpp"

namespace vines::host::monitor {

struct Series {
  std::string name;   // the --csv column
  std::string label;  // as the page shows it
  std::string unit;
  std::string panel;  // the chart: ground, floors, device, contact, stiffness, health, alarm, table, force, tracking, flags
};

// What the page is told first: the run and its series.
struct PageMeta {
  std::string source;  // the scene (live) or the CSV (view)
  std::string mode;    // replay, twin, hybrid
  bool live = true;
  double rate_hz = 0;  // sensor rate
  int every = 1;       // the page gets every this many samples
  int stories = 0;
  // The device, for its panel: "vines", "tmd" or "" (none, or not known);
  // the series of the floor it sits on, if the page has it (the sphere or
  // the mass is drawn relative to it); VI NES: the sphere's free travel each
  // side of the box's centre (the walls; 0: not known, as in a replay).
  std::string device;
  std::string device_floor_series;
  double gap_m = 0;
  std::vector<Series> series;
};
nlohmann::json to_json(const PageMeta& m);

// The series of the floor a device sits on (1-based), if the page has it:
// the top floor's, or an x_F_m of `columns`; "" if neither.
std::string device_floor_series(int floor, int stories, const std::vector<std::string>& columns);

// A series by its --csv column's name, in a mode (replay, twin, hybrid) with
// a device: its label, unit and panel.
Series describe(const std::string& name, const std::string& mode, DeviceKind device);

// Which of the device's series the node gives: the sphere or the TMD's mass
// where the node runs the device's model (replay, the open-loop twin; the
// TMD's only in double and float, fixed: false), the
// contact force (VI NES: the model's, or the twin estimator's estimate of
// the device's force on its floor), the truth's device force (twin, VI NES).
// Hybrid: none (the device is on the table; the load cell reads it).
struct DeviceSeries {
  bool particle = false, contact = false, truth_force = false;
};
DeviceSeries device_series(const std::string& mode, DeviceKind device, bool estimator, bool fixed = false);

// The page's series in their order, for the live page and its replay: the
// ground, the top floor, the device's (d), the node's flags; twin: the
// truth's top floor (and device force), the residual, then with the
// estimator the factors (`factors`: their eta_ names) and their sd, and the
// story in alarm; hybrid: the table, its command, the load cell, the
// tracking RMS; last the floors of --floors (`floors`: their x_F_m names).
std::vector<std::string> series_names(const std::string& mode, const DeviceSeries& d,
                                      const std::vector<std::string>& factors, const std::vector<std::string>& floors);

// The twin's decision, after series_names' (with the estimator: `factors`
// not empty): each story's statistic in the decision's leading test (stat_1
// ..., the evidence panel) and the absolute test's threshold
// (stat_threshold), as the twin's --csv names them; then kDecisionSeries,
// as the telemetry gives them (the banner: a second story, 0: none; the
// sizes; the onset in s, -1: none), which the twin's --csv does not write
// (yet): a replay shows them only from a CSV that has them.
inline constexpr const char* kDecisionSeries[] = {"second_story", "damage_size", "second_size", "onset_s"};
std::vector<std::string> decision_names(const std::vector<std::string>& factors);

// The series whose nonzero value makes a sample an event the page keeps
// (decimator.hpp): the model's contact force, where the node runs the VI
// NES's model (not the twin estimator's force, which is never quite 0);
// -1: none.
int event_series(const std::vector<std::string>& names, const DeviceSeries& d);

// Every how many samples the page gets one: about 200 a second of record.
int page_every(double rate_hz);

// The tracking error's running RMS in % of the target's (hybrid: the table
// against the frame's top floor, as the report's tracking_rms_pct at the end).
class RunningTracking {
 public:
  void add(double target, double measured) { se_ += (measured - target) * (measured - target), sr_ += target * target; }
  double pct() const;

 private:
  double se_ = 0, sr_ = 0;
};

// A bench run's series and their values from the record.
class BenchRows {
 public:
  explicit BenchRows(const Bench& b);
  const PageMeta& meta() const { return meta_; }
  // Whether a row (take()'s) is an event sample (event_series).
  bool event(const std::vector<double>& v) const { return event_ >= 0 && v[static_cast<std::size_t>(event_)] != 0; }
  // Sample k's telemetry came: what is held across samples is updated (the
  // twin's factors, one a step; the tracking RMS), and its row put in *v.
  void take(long long k, const HilRecord& rec, std::vector<double>* v);

 private:
  const Bench& b_;
  PageMeta meta_;
  DeviceSeries device_;
  int event_ = -1;                  // event_series
  int params_ = 0;                  // twin estimator: the factors (stories, then the device's)
  std::vector<double> eta_, sd_;    // each held from its last telemetry
  std::vector<double> stat_;        // the stories' statistics, held the same way
  RunningTracking tracking_;
};

}  // namespace vines::host::monitor
