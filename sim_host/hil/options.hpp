// What `vines hil` is asked to do: the mode, the clock, the node, the faults
// to inject and each mode's settings (the command line fills them in
// sim_host/cli/hil.cpp; run_hil in hil.hpp runs them).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim_host/hil/modes/twin_design.hpp"

namespace vines::host {

// When a fault is injected: with a probability per sample, or at samples.
struct FaultSpec {
  double rate = 0;
  std::vector<long long> at;
  bool any() const { return rate > 0 || !at.empty(); }
};

enum class FaultKind { kDrop, kCorrupt, kDuplicate, kReorder, kLate, kNonFinite, kSaturate, kStall, kRestart, kCount };
inline constexpr int kFaultKinds = static_cast<int>(FaultKind::kCount);
const char* fault_kind_name(FaultKind k);

// Parses a fault spec: "RATE" (0..1) or "@K1,K2,..."; throws naming the option.
FaultSpec parse_fault_spec(const std::string& option, const std::string& value);

// The bench's modes: replay (the scene as `vines run` runs it), twin
// (digital-twin monitor against a bench truth model), hybrid (shake table).
enum class HilMode { kReplay, kTwin, kHybrid };
// Their names (--mode, the report), in the enum's order.
inline constexpr const char* kHilModeNames[] = {"replay", "twin", "hybrid"};
inline const char* hil_mode_name(HilMode m) { return kHilModeNames[static_cast<int>(m)]; }

// The twin node's estimator: none (the open-loop twin: the scene's model on
// the ground acceleration) or kalman (docs/twin.md); names for --estimator.
enum class HilEstimator { kNone, kKalman };
inline constexpr const char* kHilEstimatorNames[] = {"none", "kalman"};

// The hybrid node's compensation of the table's delay: none, polynomial
// extrapolation, adaptive (ATS); names for --comp and the report.
enum class HilComp { kNone, kPoly, kAdaptive };
inline constexpr const char* kHilCompNames[] = {"none", "poly", "adaptive"};
inline const char* hil_comp_name(HilComp c) { return kHilCompNames[static_cast<int>(c)]; }

struct HilOptions {
  HilMode mode = HilMode::kReplay;
  bool realtime = false;
  double duration_s = 0;        // 0: the scene's
  std::string csv;              // "" : none
  std::vector<int> floors;      // floors (1-based) whose displacement --csv and the page add
  double timeout_s = 0;         // longest wait for the node (0: 5 s, 60 s for a board in QEMU)
  double deadline_periods = 1;  // telemetry k due by (k + this) h
  unsigned long long seed = 1;
  FaultSpec faults[kFaultKinds];
  int late_periods = 3, stall_periods = 20;
  double saturate_g = 0;        // sensor range (0: none)
  // node fault policy
  double grace_periods = 1.5, node_stall_periods = 10;
  // twin
  HilEstimator estimator = HilEstimator::kKalman;
  std::string truth_path;            // the measured building's scene ("" : the node's scene)
  double truth_stiffness_scale = 1;  // the bench's building (eta_k), times the truth scene's
  std::vector<int> sensors;          // floor accelerometers, 1-based (empty: the top floor)
  double measure_noise_mps2 = 0;     // sensor noise, RMS...
  double measure_noise_pct = 0;      // ...or as % of each channel's RMS
  double measure_bias_mps2 = 0;      // each sensor's bias drawn from N(0, this^2)
  double adc_lsb_mps2 = 0;           // ADC resolution (0: none)
  TwinTuning tuning;
  std::string baseline_path;         // the decision's baseline (twin_baseline.hpp; "": the drawing)
  std::string commission_path;       // the run's estimates added to this baseline file
  double drift_limit_m = 0;          // every story (0: no alarm)
  double residual_limit_mps2 = 0.05;
  double residual_window_s = 1.0;
  // hybrid
  double actuator_hz = 20, actuator_zeta = 0.7, actuator_delay_s = 0.005;
  double force_noise_n = 50, force_lsb_n = 10;
  HilComp comp = HilComp::kPoly;
  double comp_delay_s = -1;  // < 0: the actuator's delay, its lag (2 zeta / w) and the hold's h / 2
  int comp_order = 2;
  double comp_window_s = 1;  // adaptive: memory of the fit
  // The node: "host" (this program's `vines node`), "qemu:TARGET" (a board of
  // hal/mcu/boards.txt: its image in QEMU, instructions counted), or the
  // path of a program that speaks the link on stdin/stdout.
  std::string node = "host";
  std::string node_command;       // host node: the program run as `PROGRAM node` ("" : this one)
  std::string image;              // qemu: the board image ("" : the preset build's)
  std::uint32_t budget_ticks = 0; // node's deadline budget in its counter ticks (0: one period)
  // Real-time service (--realtime only): SCHED_FIFO at this priority and
  // locked memory (0: none); the cores the bench and the host node are
  // pinned to (none, the bench's, or both).
  int rt_priority = 0;
  std::vector<int> cpus;
  int bench_cpu() const { return cpus.empty() ? -1 : cpus[0]; }
  int node_cpu() const { return cpus.size() < 2 ? -1 : cpus[1]; }
};

}  // namespace vines::host
