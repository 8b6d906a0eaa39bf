// The report of a `vines hil` run as typed structs: what the bench measured
// (steps, deadlines, latency, faults, deviation from the offline run), the
// node's own deadline monitor, and each mode's results. to_json gives the
// report `vines hil --json` prints; write_hil_csv the per-step rows of --csv.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/hil/link/realtime.hpp"
#include "sim_host/hil/options.hpp"
#include "sim_host/scene/scalar.hpp"
#include "vines/link/messages.hpp"

namespace vines::host {

struct HilRecord;

// A mode's own columns of the per-step CSV: names, and rows[k] the values at
// sample k.
struct CsvColumns {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
};

// Mean and quantiles of a set of values.
struct HilStats {
  double mean = 0, p50 = 0, p99 = 0, max = 0;
};

// Faults of one kind: how many were injected, detected by the node, survived
// (all or none: the kind is judged as a whole, docs/link_protocol.md), and
// the verdict's figures: the largest deviation of the top floor from the
// clean run after the recovery windows, its bound, and the samples judged
// that got no telemetry.
struct HilFaultCounts {
  long long injected = 0, detected = 0, survived = 0;
  bool ok = true;
  double deviation_m = 0, bound_m = 0;
  long long unanswered = 0;
};

// The node's last status: steps taken, state, and how its process ended.
struct HilNodeStatus {
  std::uint32_t steps = 0;
  int state = 0;        // link::NodeState
  int exit_status = 0;  // its process's (128 + signal if killed)
};

// A board in QEMU: its steps' cost in instructions (-icount counts them).
struct HilBoardSteps {
  int icount_shift = 0;
  double worst_step_instructions = 0;
  std::uint32_t worst_step_k = 0;
  double median_step_instructions = 0;
};

// Twin mode, the device's health as the estimator sees it (docs/twin.md
// section 6): a VI NES's impulses, impacts and added mass against the
// truth's; a TMD's frequency against its design.
struct HilTwinDevice {
  std::string kind = "none";
  // VI NES
  double impulse_estimated_ns = 0, impulse_truth_ns = 0;
  long long impacts_estimated = 0, contacts_truth = 0;
  double added_mass_ratio = 0;   // the mass the device's floor gained (estimated), over the sphere's
  // The device floor's absolute travel over the run (estimated: the ground's
  // displacement plus the floor's), and the sphere's free travel in its box.
  double floor_travel_m = 0, free_travel_m = 0;
  // "moving"; "stuck" (moves with its floor: its mass gained by the floor, or
  // no impact seen where the floor travelled a quarter beyond the sphere's
  // free travel, so that a free sphere must have hit); "still" (no impact seen)
  std::string sphere;
  // TMD
  double frequency_factor = 1, frequency_factor_sd = 0, truth_frequency_factor = 1;
  bool detuned = false;
};

// Twin mode: with the estimator, what it says of the building against the
// truth; and, as for the open-loop twin, the residual of the top floor
// against its measurement, alarms.
struct HilTwinReport {
  std::string estimator = "kalman";
  std::string truth;                       // the truth's scene ("" : the node's own)
  std::vector<double> truth_story_scales;  // each story's stiffness factor in the truth (before its damage)
  std::optional<double> truth_damage_time_s;       // when the truth's [damage] struck (none: no [damage])
  std::vector<double> truth_damaged_story_scales;  // each story's factor after it (truth_story_scales without)
  std::vector<int> sensors;
  std::vector<double> noise_sd_mps2;
  bool detected = false;
  std::optional<int> story;                // 1-based; none when detected with no story identified
  bool story_identified = false;           // detected and a story named
  std::vector<int> stories;                // the stories named (one or two), 1-based
  std::vector<double> sizes;               // their losses
  // detect_delay_s: from truth_damage_time_s when the truth has one, else
  // from strong_motion_start_s.
  std::optional<double> size, detect_time_s, detect_delay_s;
  std::optional<double> onset_s;           // when the node estimates the change happened
  std::string caveat;                      // why the verdict may be wrong ("": none seen)
  double strong_motion_start_s = 0;
  std::vector<double> eta_k, eta_k_sd;     // at the end, per story
  std::optional<double> roof_displacement_nrmse;  // RMS error over the truth's RMS
  double roof_displacement_sd_m = 0;       // the design's steady-state sd
  HilTwinDevice device;
  double truth_stiffness_scale = 1;
  double residual_rms_mps2 = 0, residual_max_mps2 = 0, residual_limit_mps2 = 0;
  long long residual_alarm_steps = 0;
  std::optional<double> first_residual_alarm_s;
  double drift_limit_m = 0;
  long long drift_alarm_steps = 0;
  std::optional<double> first_drift_alarm_s;
  std::vector<int> stories_alarmed;  // from 1
};

// The adaptive compensator's coefficients a0, a1 [s], a2 [s^2] (link/ats.hpp):
// at the end of the run, and their least and largest over it.
struct HilAtsCoefficients {
  double last[3] = {}, min[3] = {}, max[3] = {};
};

// Hybrid mode: the actuator, its compensation, the tracking of the table and
// the top floor against the pure simulation, and the vRTHS benchmark's
// criteria (rths_criteria.hpp; none where the reference is zero throughout
// or the delay is beyond the search).
struct HilHybridReport {
  double actuator_hz = 0, actuator_zeta = 0, actuator_delay_s = 0;
  HilComp compensation = HilComp::kPoly;
  double compensation_delay_s = 0;  // polynomial: the delay extrapolated over; adaptive: initial a1
  int compensation_order = 0;
  double compensation_window_s = 0;
  std::optional<HilAtsCoefficients> adaptive;  // adaptive only
  double force_noise_n = 0, force_lsb_n = 0;
  double tracking_rms_m = 0, tracking_peak_m = 0;
  double top_diff_from_pure_rms_m = 0, top_diff_from_pure_peak_m = 0;
  double peak_top_hybrid_m = 0, peak_top_pure_m = 0;
  std::optional<double> tracking_delay_ms, tracking_rms_pct, tracking_peak_pct;
  std::vector<std::optional<double>> response_rms_pct, response_peak_pct;  // per floor, bottom first
  // The paper's reductions against the bare frame on the same record (peak
  // top-floor displacement, E_e), of the hybrid and of the pure simulation:
  // a chaotic specimen is judged by these over many runs, not by one
  // trajectory (tools/hybrid_statistics.sh).
  double x_r_hybrid = 0, x_r_pure = 0, E_r_hybrid = 0, E_r_pure = 0;
};

struct HilReport {
  std::string scene;
  HilMode mode = HilMode::kReplay;
  bool realtime = false;
  Scalar scalar = Scalar::kDouble;
  double sensor_rate_hz = 0;
  // Steps and deadlines
  long long samples = 0, steps = 0, missing_steps = 0;
  double deadline_s = 0;
  long long deadline_misses = 0;
  std::optional<HilStats> latency_us;  // none without a step
  // Faults: injected by the bench (by kind), counted by the node (by code)
  long long faults_injected = 0, faults_detected = 0, faults_survived = 0;
  std::map<std::string, HilFaultCounts> faults;
  bool survived = true;         // every kind survived (no faults: true)
  double survival_bound_m = 0;  // the bound: the clean run's peak top-floor displacement
  std::map<std::string, long long> node_faults;
  long long node_restarts = 0, bad_frames_from_node = 0;
  // Against the offline run
  double max_deviation_from_offline = 0;
  bool bit_exact = false, outputs_finite = true;
  double max_abs_floor_displacement_m = 0;
  // The node: status, its deadline monitor and its steps' cost from telemetry
  HilNodeStatus node_status;
  std::string node;
  link::StepTiming node_deadline;
  std::optional<HilStats> step_ticks;
  long long steps_over_budget = 0;  // from telemetry: equals the monitor's overruns on a clean run
  std::optional<HilBoardSteps> board;
  double wall_time_s = 0;
  // Real-time service, when asked for: the bench's, the host node's
  std::optional<RealtimeGrant> bench_service, node_service;
  // The modes' own results
  std::optional<HilTwinReport> twin;
  std::optional<HilHybridReport> hybrid;
};

// The report as `vines hil --json` prints it.
nlohmann::json to_json(const HilReport& r);

// Writes --csv: one row per sample (hybrid: with the table and the load cell;
// then the mode's columns, then x_F_m of each of `floors`, 1-based); returns
// its column count. Throws naming the file if it cannot be written.
int write_hil_csv(const std::string& path, const HilRecord& rec, const std::vector<link::Telemetry>& offline,
                  int stories, double h, const CsvColumns& extra = {}, const std::vector<int>& floors = {});

// What a --csv cannot say of its run, written beside it as PATH.json for
// `vines view`: the format and its column count, the mode, the scene, the
// sensor rate, the stories, the device (kind, floor, the VI NES box's free
// travel) and the floors of its x_F_m columns.
// A device as the page and the --csv's description name it: its kind
// ("none", "tmd", "vines"), its floor (1-based; 0: none) and the VI NES box's
// free travel each side [m] (0 otherwise).
struct DeviceLayout {
  std::string kind = "none";
  int floor = 0;
  double gap_m = 0;
};

struct CsvMeta {
  std::string mode, scene;
  double rate_hz = 0;
  int stories = 0, columns = 0;
  DeviceLayout device;
  std::vector<int> floors;
};
nlohmann::json to_json(const CsvMeta& m);
void write_hil_csv_meta(const std::string& csv_path, const CsvMeta& m);

}  // namespace vines::host
