#include "sim_host/monitor/rows.hpp"

#include <algorithm>
#include <cmath>

namespace vines::host::monitor {

nlohmann::json to_json(const PageMeta& m) {
  nlohmann::json s = nlohmann::json::array();
  for (const Series& x : m.series)
    s.push_back({{"name", x.name}, {"label", x.label}, {"unit", x.unit}, {"panel", x.panel}});
  return {{"source", m.source}, {"mode", m.mode}, {"live", m.live}, {"rate_hz", m.rate_hz},
          {"every", m.every},   {"stories", m.stories}, {"series", s}};
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
  if (name == "table_x_m") return {name, "table", "m", "floors"};
  if (name == "force_measured_n") return {name, "load cell", "N", "force"};
  if (name == "tracking_rms_pct") return {name, "tracking error RMS so far", "%", "tracking"};
  if (name.size() > 4 && name.rfind("x_", 0) == 0 && name.substr(name.size() - 2) == "_m" &&
      name.find_first_not_of("0123456789", 2) == name.size() - 2)
    return {name, "floor " + name.substr(2, name.size() - 4), "m", "floors"};
  if (name.rfind("eta_sd_", 0) == 0) return {name, "sd", "", "band"};
  if (name == "eta_" + device_name) return {name, device_name, "", "health"};
  if (name.rfind("eta_", 0) == 0) return {name, "story " + name.substr(4), "", "stiffness"};
  return {name, name, "", "other"};
}

DeviceSeries device_series(const std::string& mode, DeviceKind device, bool estimator) {
  DeviceSeries d;
  d.particle = device != DeviceKind::kNone && (mode == "replay" || (mode == "twin" && !estimator));
  d.contact = device == DeviceKind::kVines && mode != "hybrid";
  d.truth_force = device == DeviceKind::kVines && mode == "twin";
  return d;
}

BenchRows::BenchRows(const Bench& b) : b_(b) {
  const SceneParams& p = b.scene.params;
  const DeviceKind dev = p.device.kind;
  meta_.source = b.scene.path;
  meta_.mode = hil_mode_name(b.opt.mode);
  meta_.rate_hz = 1 / b.h;
  meta_.every = page_every(meta_.rate_hz);
  meta_.stories = p.frame.stories;
  // Every mode: the ground, the top floor, the device, the node's flags;
  // then the mode's own (the order of take()). The twin's estimator has no
  // device model: it gives the device's force it estimates, not the sphere.
  const bool estimator = b.opt.mode == HilMode::kTwin && b.cfg.estimator == link::TwinEstimator::kKalman;
  device_ = device_series(meta_.mode, dev, estimator);
  std::vector<std::string> names = {"ag_sent_mps2", "x_top_m"};
  if (device_.particle) names.push_back("particle_x_m");
  if (device_.contact) names.push_back("contact_force_n");
  names.push_back("flags");
  if (b.opt.mode == HilMode::kTwin) {
    names.push_back("x_top_truth_m");
    if (device_.truth_force) names.push_back("device_force_truth_n");
    names.push_back("aux");
    if (estimator) {
      // The stories' factors, then the device's, as the twin's --csv names them.
      params_ = meta_.stories + (dev == DeviceKind::kNone ? 0 : 1);
      eta_.assign(static_cast<std::size_t>(params_), 1.0);
      sd_.assign(static_cast<std::size_t>(params_), 0.0);
      const auto param = [&](int j) {
        return j < meta_.stories ? std::to_string(j + 1) : dev == DeviceKind::kTmd ? "tmd" : "device_floor_mass";
      };
      for (int j = 0; j < params_; ++j) names.push_back("eta_" + param(j));
      for (int j = 0; j < params_; ++j) names.push_back("eta_sd_" + param(j));
      names.push_back("alarm_story");
    }
  } else if (b.opt.mode == HilMode::kHybrid) {
    for (const char* c : {"table_x_m", "aux", "force_measured_n", "tracking_rms_pct"}) names.push_back(c);
  }
  // The floors chosen (--floors), last.
  for (int f : b.opt.floors) names.push_back("x_" + std::to_string(f) + "_m");
  for (const std::string& n : names) meta_.series.push_back(describe(n, meta_.mode, dev));
}

void BenchRows::take(long long k, const HilRecord& rec, std::vector<double>* v) {
  const auto i = static_cast<std::size_t>(k);
  const link::Telemetry& t = rec.tel[i];
  const int n = meta_.stories;
  if (t.est_index < eta_.size()) eta_[t.est_index] = t.est_eta, sd_[t.est_index] = t.est_sd;
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
}

}  // namespace vines::host::monitor
