#include "sim_host/monitor/rows.hpp"

#include <algorithm>
#include <cmath>


namespace vines::host::monitor {

nlohmann::json to_json(const PageMeta& m) {
  nlohmann::json s = nlohmann::json::array();
  for (const Series& x : m.series)
    s.push_back({{"name", x.name}, {"label", x.label}, {"unit", x.unit}, {"panel", x.panel}});
  return {{"source", m.source},
          {"mode", m.mode},
          {"live", m.live},
          {"rate_hz", m.rate_hz},
          {"every", m.every},
          {"stories", m.stories},
          {"device", {{"kind", m.device}, {"floor_series", m.device_floor_series}, {"gap_m", m.gap_m}}},
          {"series", s}};
}

int page_every(double rate_hz) { return std::max(1, static_cast<int>(std::lround(rate_hz / 200))); }

double RunningTracking::pct() const { return sr_ > 0 ? 100 * std::sqrt(se_ / sr_) : 0.0; }

Series describe(const std::string& name, const std::string& mode, DeviceKind device) {
  const std::string device_name = device == DeviceKind::kTmd ? "tmd" : "device_floor_mass";
  if (name == "ag_sent_mps2") return {name, "ground acceleration", "m/s^2", "ground"};
  if (name == "x_top_m") return {name, mode == "twin" ? "top floor (twin)" : "top floor", "m", "floors"};
  if (name == "particle_x_m")
    return {name, device == DeviceKind::kTmd ? "TMD mass" : "sphere in its box", "m", "device"};
  if (name == "contact_force_n")
    return {name, mode == "twin" ? "device force (twin)" : "contact force", "N", "contact"};
  if (name == "device_force_truth_n") return {name, "device force (truth)", "N", "contact"};
  if (name == "flags") return {name, "node flags", "", "flags"};
  if (name == "x_top_truth_m") return {name, "top floor (truth)", "m", "floors"};
  if (name == "aux" && mode == "twin") return {name, "top floor residual", "m/s^2", "residual"};
  if (name == "aux") return {name, "table command", "m", "floors"};
  if (name == "alarm_story") return {name, "story in alarm", "", "alarm"};
  // The twin's decision: each story's statistic and the threshold (the
  // evidence panel), the second story, the sizes and the onset (the banner).
  if (name == "stat_threshold") return {name, "threshold", "", "evidence"};
  if (name.size() > 5 && name.rfind("stat_", 0) == 0 && name.find_first_not_of("0123456789", 5) == std::string::npos)
    return {name, "story " + name.substr(5), "", "evidence"};
  if (name == "second_story") return {name, "second story", "", "decision"};
  if (name == "damage_size") return {name, "damage size", "", "decision"};
  if (name == "second_size") return {name, "second story's size", "", "decision"};
  if (name == "onset_s") return {name, "onset", "s", "decision"};
  if (name == "table_x_m") return {name, "table", "m", "floors"};
  if (name == "force_measured_n") return {name, "load cell", "N", "force"};
  if (name == "tracking_rms_pct") return {name, "tracking error RMS so far", "%", "tracking"};
  if (name.size() > 4 && name.rfind("x_", 0) == 0 && name.substr(name.size() - 2) == "_m" &&
      name.find_first_not_of("0123456789", 2) == name.size() - 2)
    return {name, "floor " + name.substr(2, name.size() - 4), "m", "floors"};
  if (name.rfind("eta_sd_", 0) == 0) return {name, "sd", "", "band"};
  if (name == "eta_" + device_name)
    return {name, device == DeviceKind::kTmd ? "TMD spring (factor)" : "device floor's mass (factor)", "", "health"};
  if (name.rfind("eta_", 0) == 0) return {name, "story " + name.substr(4), "", "stiffness"};
  return {name, name, "", "other"};
}

DeviceSeries device_series(const std::string& mode, DeviceKind device, bool estimator, bool fixed) {
  DeviceSeries d;
  d.particle = device != DeviceKind::kNone && !(device == DeviceKind::kTmd && fixed) &&
               (mode == "replay" || (mode == "twin" && !estimator));
  d.contact = device == DeviceKind::kVines && mode != "hybrid";
  d.truth_force = device == DeviceKind::kVines && mode == "twin";
  return d;
}

std::vector<std::string> series_names(const std::string& mode, const DeviceSeries& d,
                                      const std::vector<std::string>& factors, const std::vector<std::string>& floors) {
  std::vector<std::string> names = {"ag_sent_mps2", "x_top_m"};
  if (d.particle) names.push_back("particle_x_m");
  if (d.contact) names.push_back("contact_force_n");
  names.push_back("flags");
  if (mode == "twin") {
    names.push_back("x_top_truth_m");
    if (d.truth_force) names.push_back("device_force_truth_n");
    names.push_back("aux");
    if (!factors.empty()) {
      names.insert(names.end(), factors.begin(), factors.end());
      for (const std::string& f : factors) names.push_back("eta_sd_" + f.substr(4));
      names.push_back("alarm_story");
    }
  } else if (mode == "hybrid") {
    for (const char* c : {"table_x_m", "aux", "force_measured_n", "tracking_rms_pct"}) names.push_back(c);
  }
  names.insert(names.end(), floors.begin(), floors.end());
  return names;
}

std::vector<std::string> decision_names(const std::vector<std::string>& factors) {
  std::vector<std::string> names;
  if (factors.empty()) return names;
  for (const std::string& f : factors)
    if (f.find_first_not_of("0123456789", 4) == std::string::npos) names.push_back("stat_" + f.substr(4));
  names.push_back("stat_threshold");
  names.insert(names.end(), std::begin(kDecisionSeries), std::end(kDecisionSeries));
  return names;
}

int event_series(const std::vector<std::string>& names, const DeviceSeries& d) {
  if (!d.particle || !d.contact) return -1;
  const auto it = std::find(names.begin(), names.end(), "contact_force_n");
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

namespace {

// The device's panel: its kind, the floor it sits on (if on the page) and
// the VI NES box's walls, as the scene's model designs them.
void set_device(const Bench& b, const std::vector<std::string>& floors, PageMeta* m) {
  const DeviceLayout d = device_layout(b.scene);
  m->device = d.kind;
  m->device_floor_series = device_floor_series(d.floor, b.scene.params.frame.stories, floors);
  m->gap_m = d.gap_m;
}

}  // namespace

std::string device_floor_series(int floor, int stories, const std::vector<std::string>& columns) {
  if (floor == stories) return "x_top_m";
  const std::string x = "x_" + std::to_string(floor) + "_m";
  return std::find(columns.begin(), columns.end(), x) != columns.end() ? x : "";
}

BenchRows::BenchRows(const Bench& b) : b_(b) {
  const SceneParams& p = b.scene.params;
  const DeviceKind dev = p.device.kind;
  meta_.source = b.scene.path;
  meta_.mode = hil_mode_name(b.opt.mode);
  meta_.rate_hz = 1 / b.h;
  meta_.every = page_every(meta_.rate_hz);
  meta_.stories = p.frame.stories;
  // The series (series_names), in the order take() gives their values. The
  // twin's estimator has no device model: it gives the device's force it
  // estimates, not the sphere.
  const bool estimator = b.opt.mode == HilMode::kTwin && b.cfg.estimator == link::TwinEstimator::kKalman;
  device_ = device_series(meta_.mode, dev, estimator, b.scene.scalar == Scalar::kFixed);
  std::vector<std::string> factors, floors;
  if (estimator) {
    // The stories' factors, then the device's, as the twin's --csv names them.
    params_ = meta_.stories + (dev == DeviceKind::kNone ? 0 : 1);
    eta_.assign(static_cast<std::size_t>(params_), 1.0);
    sd_.assign(static_cast<std::size_t>(params_), 0.0);
    stat_.assign(static_cast<std::size_t>(meta_.stories), 0.0);
    for (int j = 0; j < params_; ++j)
      factors.push_back("eta_" + (j < meta_.stories          ? std::to_string(j + 1)
                                  : dev == DeviceKind::kTmd ? std::string("tmd")
                                                            : std::string("device_floor_mass")));
  }
  for (int f : b.opt.floors) floors.push_back("x_" + std::to_string(f) + "_m");
  std::vector<std::string> names = series_names(meta_.mode, device_, factors, floors);
  for (const std::string& n : decision_names(factors)) names.push_back(n);
  event_ = event_series(names, device_);
  for (const std::string& n : names) meta_.series.push_back(describe(n, meta_.mode, dev));
  if (dev != DeviceKind::kNone) set_device(b, floors, &meta_);
}

void BenchRows::take(long long k, const HilRecord& rec, std::vector<double>* v) {
  const auto i = static_cast<std::size_t>(k);
  const link::Telemetry& t = rec.tel[i];
  const int n = meta_.stories;
  if (t.est_index < eta_.size()) eta_[t.est_index] = t.est_eta, sd_[t.est_index] = t.est_sd;
  if (t.est_index < stat_.size()) stat_[t.est_index] = t.est_stat;
  v->clear();
  v->push_back(rec.sensed[i]);
  v->push_back(t.x[n - 1]);
  if (device_.particle) v->push_back(t.particle_x);
  if (device_.contact) v->push_back(t.contact_force);
  v->push_back(t.flags);
  if (b_.opt.mode == HilMode::kTwin) {
    v->push_back(b_.twin.truth.roof_x[i]);
    if (device_.truth_force) v->push_back(b_.twin.truth.device_force[i]);
    v->push_back(t.aux);
    if (params_ > 0) {
      v->insert(v->end(), eta_.begin(), eta_.end());
      v->insert(v->end(), sd_.begin(), sd_.end());
      v->push_back(t.alarm_story);
    }
  } else if (b_.opt.mode == HilMode::kHybrid) {
    tracking_.add(t.x[n - 1], rec.table_x[i]);
    v->push_back(rec.table_x[i]);
    v->push_back(t.aux);
    v->push_back(rec.force[i]);
    v->push_back(tracking_.pct());
  }
  for (int f : b_.opt.floors) v->push_back(t.x[f - 1]);
  if (params_ > 0) {
    v->insert(v->end(), stat_.begin(), stat_.end());
    v->push_back(t.stat_threshold);
    for (double x : {static_cast<double>(t.second_story), t.damage_size, t.second_size, t.onset_s}) v->push_back(x);
  }
}

}  // namespace vines::host::monitor
