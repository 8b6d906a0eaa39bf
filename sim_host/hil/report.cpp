#include "sim_host/hil/report.hpp"

#include <cmath>
#include <iterator>

#include "sim_host/hil/record.hpp"
#include "sim_host/io/csv.hpp"
#include "sim_host/io/output.hpp"

namespace vines::host {
namespace {

using nlohmann::json;

json to_json(const std::optional<HilStats>& s) {
  if (!s) return nullptr;
  return {{"mean", s->mean}, {"p50", s->p50}, {"p99", s->p99}, {"max", s->max}};
}

json to_json(const std::optional<double>& x) { return x ? json(*x) : json(nullptr); }

json to_json(const std::vector<std::optional<double>>& xs) {
  json a = json::array();
  for (const auto& x : xs) a.push_back(to_json(x));
  return a;
}

json to_json(const HilTwinDevice& d) {
  json j = {{"kind", d.kind}};
  if (d.kind == "vines")
    j.update({{"impulse_estimated_ns", d.impulse_estimated_ns},
              {"impulse_truth_ns", d.impulse_truth_ns},
              {"impacts_estimated", d.impacts_estimated},
              {"contacts_truth", d.contacts_truth},
              {"added_mass_ratio", d.added_mass_ratio},
              {"floor_travel_m", d.floor_travel_m},
              {"free_travel_m", d.free_travel_m},
              {"sphere", d.sphere}});
  if (d.kind == "tmd")
    j.update({{"frequency_factor", d.frequency_factor},
              {"frequency_factor_sd", d.frequency_factor_sd},
              {"truth_frequency_factor", d.truth_frequency_factor},
              {"detuned", d.detuned}});
  return j;
}

json to_json(const HilTwinReport& t) {
  json j = {{"estimator", t.estimator},
            {"truth", t.truth},
            {"truth_story_scales", t.truth_story_scales},
            {"truth_damage_time_s", to_json(t.truth_damage_time_s)},
            {"truth_damaged_story_scales", t.truth_damaged_story_scales},
            {"sensors", t.sensors},
            {"noise_sd_mps2", t.noise_sd_mps2},
            {"strong_motion_start_s", t.strong_motion_start_s}};
  if (t.estimator != "none")
    j.update({{"detected", t.detected},
              {"story", t.story ? json(*t.story) : json(nullptr)},
              {"story_identified", t.story_identified},
              {"stories", t.stories},
              {"sizes", t.sizes},
              {"size", to_json(t.size)},
              {"onset_s", to_json(t.onset_s)},
              {"caveat", t.caveat.empty() ? json(nullptr) : json(t.caveat)},
              {"detect_time_s", to_json(t.detect_time_s)},
              {"detect_delay_s", to_json(t.detect_delay_s)},
              {"eta_k", t.eta_k},
              {"eta_k_sd", t.eta_k_sd},
              {"roof_displacement_nrmse", to_json(t.roof_displacement_nrmse)},
              {"roof_displacement_sd_m", t.roof_displacement_sd_m},
              {"device", to_json(t.device)}});
  j.update({{"truth_stiffness_scale", t.truth_stiffness_scale},
          {"residual_rms_mps2", t.residual_rms_mps2},
          {"residual_max_mps2", t.residual_max_mps2},
          {"residual_limit_mps2", t.residual_limit_mps2},
          {"residual_alarm_steps", t.residual_alarm_steps},
          {"first_residual_alarm_s", to_json(t.first_residual_alarm_s)},
          {"drift_limit_m", t.drift_limit_m},
          {"drift_alarm_steps", t.drift_alarm_steps},
          {"first_drift_alarm_s", to_json(t.first_drift_alarm_s)},
          {"stories_alarmed", t.stories_alarmed}});
  return j;
}

json to_json(const std::optional<HilAtsCoefficients>& a) {
  if (!a) return nullptr;
  json j;
  const char* names[3] = {"a0", "a1_s", "a2_s2"};
  for (int i = 0; i < 3; ++i) j[names[i]] = {{"last", a->last[i]}, {"min", a->min[i]}, {"max", a->max[i]}};
  return j;
}

json to_json(const HilHybridReport& h) {
  return {{"actuator", {{"hz", h.actuator_hz}, {"zeta", h.actuator_zeta}, {"delay_s", h.actuator_delay_s}}},
          {"compensation", hil_comp_name(h.compensation)},
          {"compensation_delay_s", h.compensation_delay_s},
          {"compensation_order", h.compensation_order},
          {"compensation_window_s", h.compensation_window_s},
          {"adaptive", to_json(h.adaptive)},
          {"force_noise_n", h.force_noise_n},
          {"force_lsb_n", h.force_lsb_n},
          {"tracking_rms_m", h.tracking_rms_m},
          {"tracking_peak_m", h.tracking_peak_m},
          {"top_diff_from_pure_rms_m", h.top_diff_from_pure_rms_m},
          {"top_diff_from_pure_peak_m", h.top_diff_from_pure_peak_m},
          {"peak_top_hybrid_m", h.peak_top_hybrid_m},
          {"peak_top_pure_m", h.peak_top_pure_m},
          {"tracking_delay_ms", to_json(h.tracking_delay_ms)},
          {"tracking_rms_pct", to_json(h.tracking_rms_pct)},
          {"tracking_peak_pct", to_json(h.tracking_peak_pct)},
          {"response_rms_pct", to_json(h.response_rms_pct)},
          {"response_peak_pct", to_json(h.response_peak_pct)},
          {"x_r_hybrid", h.x_r_hybrid},
          {"x_r_pure", h.x_r_pure},
          {"E_r_hybrid", h.E_r_hybrid},
          {"E_r_pure", h.E_r_pure}};
}

}  // namespace

json to_json(const HilReport& r) {
  json j;
  // The run
  j["scene"] = r.scene;
  j["mode"] = hil_mode_name(r.mode);
  j["clock"] = r.realtime ? "realtime" : "virtual";
  j["scalar"] = scalar_name(r.scalar);
  j["sensor_rate_hz"] = r.sensor_rate_hz;
  // Steps and deadlines
  j["samples"] = r.samples;
  j["steps"] = r.steps;
  j["missing_steps"] = r.missing_steps;
  j["deadline_s"] = r.deadline_s;
  j["deadline_misses"] = r.deadline_misses;
  j["latency_us"] = to_json(r.latency_us);
  // Faults
  j["faults_injected"] = r.faults_injected;
  j["faults_detected"] = r.faults_detected;
  j["faults_survived"] = r.faults_survived;
  j["faults"] = json::object();
  for (const auto& [name, c] : r.faults)
    j["faults"][name] = {{"injected", c.injected},       {"detected", c.detected},
                         {"survived", c.survived},       {"verdict", c.ok ? "survived" : "not survived"},
                         {"deviation_m", c.deviation_m}, {"bound_m", c.bound_m},
                         {"unanswered", c.unanswered}};
  j["survived"] = r.survived;
  j["survival_bound_m"] = r.survival_bound_m;
  j["node_faults"] = json::object();
  for (const auto& [name, count] : r.node_faults) j["node_faults"][name] = count;
  j["node_restarts"] = r.node_restarts;
  j["bad_frames_from_node"] = r.bad_frames_from_node;
  // Against the offline run
  j["max_deviation_from_offline"] = r.max_deviation_from_offline;
  j["bit_exact"] = r.bit_exact;
  j["outputs_finite"] = r.outputs_finite;
  j["max_abs_floor_displacement_m"] = r.max_abs_floor_displacement_m;
  // The node
  j["node_status"] = {{"steps", r.node_status.steps}, {"state", r.node_status.state},
                      {"exit_status", r.node_status.exit_status}};
  const link::StepTiming& tm = r.node_deadline;
  j["node"] = r.node;
  j["node_deadline"] = {{"counter_hz", tm.counter_hz},   {"budget_ticks", tm.budget_ticks},
                        {"overruns", tm.overruns},       {"worst_ticks", tm.worst_ticks},
                        {"worst_k", tm.worst_k},         {"stack_peak_bytes", tm.stack_peak_bytes}};
  j["step_ticks"] = to_json(r.step_ticks);
  j["steps_over_budget"] = r.steps_over_budget;
  if (r.board) {
    j["icount_shift"] = r.board->icount_shift;
    j["worst_step_instructions"] = r.board->worst_step_instructions;
    j["worst_step_k"] = r.board->worst_step_k;
    j["median_step_instructions"] = r.board->median_step_instructions;
  }
  j["wall_time_s"] = r.wall_time_s;
  if (r.bench_service) {
    j["realtime_service"]["bench"] = to_json(*r.bench_service);
    j["realtime_service"]["node"] = r.node_service ? to_json(*r.node_service) : nlohmann::json(nullptr);
  }
  // The modes
  if (r.twin) j["twin"] = to_json(*r.twin);
  if (r.hybrid) j["hybrid"] = to_json(*r.hybrid);
  return j;
}

int write_hil_csv(const std::string& path, const HilRecord& rec, const std::vector<link::Telemetry>& offline,
                  int stories, double h, const CsvColumns& extra, const std::vector<int>& floors) {
  CsvWriter f(path);

  const bool hybrid = !rec.table_x.empty();
  const int n = stories;
  // Header, then one row per sample (a sample without telemetry: zeros).
  constexpr const char* kColumns[] = {"k", "t_s", "ag_sent_mps2", "ag_used_mps2", "received", "flags",
                                      "latency_us", "x_top_m", "x_top_offline_m", "deviation_m", "acc_top_mps2",
                                      "Ee_Js", "particle_x_m", "contact_force_n", "dissipated_J", "aux", "drift_alarms"};
  for (const char* c : kColumns) f.raw(c);
  if (hybrid) f.raw("table_x_m").raw("force_measured_n");
  for (const std::string& c : extra.names) f.raw(c);
  for (int fl : floors) f.raw("x_" + std::to_string(fl) + "_m");
  f.end_row();
  const int columns = static_cast<int>(std::size(kColumns) + (hybrid ? 2 : 0) + extra.names.size() + floors.size());
  constexpr const char* kFull = "%.17g";
  for (long long k = 0; k < rec.samples; ++k) {
    const link::Telemetry& t = rec.tel[k];
    const bool got = rec.got[k];
    f.integer(k).number(static_cast<double>(k) * h, "%.6f").number(rec.sensed[k], kFull).number(t.ag, kFull);
    f.integer(got ? 1 : 0).integer(t.flags).number(1e6 * rec.latency(k).value_or(0.0), "%.1f");
    f.number(t.x[n - 1], kFull).number(offline[k].x[n - 1], kFull);
    f.number(got ? std::fabs(t.x[n - 1] - offline[k].x[n - 1]) : 0.0, "%.3g");
    for (double v : {t.acc_top, t.elastic_energy, t.particle_x, t.contact_force, t.dissipated, t.aux}) f.number(v, kFull);
    f.raw(std::to_string(static_cast<unsigned long long>(t.drift_alarms)));
    if (hybrid) f.number(rec.table_x[k], kFull).number(rec.force[k], kFull);
    if (!extra.names.empty())
      for (double v : extra.rows[static_cast<std::size_t>(k)]) f.number(v, "%.9g");
    for (int fl : floors) f.number(t.x[fl - 1], kFull);
    f.end_row();
  }
  f.close();
  return columns;
}

nlohmann::json to_json(const CsvMeta& m) {
  return {{"format", "vines hil --csv"}, {"columns", m.columns},     {"mode", m.mode},
          {"scene", m.scene},            {"sensor_rate_hz", m.rate_hz}, {"stories", m.stories},
          {"device", {{"kind", m.device.kind}, {"floor", m.device.floor}, {"gap_m", m.device.gap_m}}},
          {"floors", m.floors}};
}

void write_hil_csv_meta(const std::string& csv_path, const CsvMeta& m) {
  write_file_atomic(csv_path + ".json", to_json(m).dump(2) + "\n");
}

}  // namespace vines::host
