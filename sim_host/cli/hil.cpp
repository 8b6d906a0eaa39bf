// `vines hil SCENE.toml`: the hardware-in-the-loop bench around `vines node`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/cli/hil_print.hpp"
#include "sim_host/cli/serve.hpp"
#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/link/serial.hpp"
#include "sim_host/hil/link/tcp.hpp"
#include "sim_host/hil/modes/twin_baseline.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::cli {
namespace {

struct HilArgs {
  std::string scene_path;
  host::HilOptions opt;
  bool as_json = false;
  bool accept_degraded = false;
  std::string serve;              // --serve ("" : no page)
  double serve_hold_s = 0;        // --serve-hold (0: the clients then connected get 2 s)
  const CLI::App* cmd = nullptr;  // for the options given (check_options)
};

// Option groups that belong to one mode (their names, as --help shows them).
const char* const kTwinGroup = "twin options";
const char* const kTuningGroup = "twin estimator tuning (docs/twin.md section 4)";
const char* const kHybridGroup = "hybrid options";

// An option given that does not apply is a usage error, not ignored: another
// mode's options, --image without a board.
void check_options(const HilArgs& a) {
  const host::HilOptions& o = a.opt;
  for (const CLI::Option* opt : a.cmd->get_options()) {
    if (opt->count() == 0) continue;
    const std::string& g = opt->get_group();
    if ((g == kTwinGroup || g == kTuningGroup) && o.mode != host::HilMode::kTwin)
      throw CLI::ValidationError(opt->get_name(), "a twin option: it needs --mode twin");
    if (g == kHybridGroup && o.mode != host::HilMode::kHybrid)
      throw CLI::ValidationError(opt->get_name(), "a hybrid option: it needs --mode hybrid");
  }
  if (!o.commission_path.empty() && o.estimator != host::HilEstimator::kKalman)
    throw CLI::ValidationError("--commission", "it needs the estimator (--estimator kalman)");
  if (!o.commission_path.empty() && !o.baseline_path.empty())
    throw CLI::ValidationError("--commission", "a commissioning run is on the healthy building: no --baseline");
  if (a.cmd->count("--serve-hold") > 0 && a.serve.empty())
    throw CLI::ValidationError("--serve-hold", "it needs --serve");
  if (a.cmd->count("--image") > 0 && o.node.rfind("qemu:", 0) != 0)
    throw CLI::ValidationError("--image", "a board image: it needs --node qemu:TARGET");
}

int hil(const HilArgs& a) {
  check_options(a);
  const host::Scene scene = host::load_scene(a.scene_path);
  if (!a.opt.commission_path.empty())
    host::check_commission_file(a.opt.commission_path, host::twin_building(scene, a.opt));
  // The page (--serve) listens before the bench starts; after the run its
  // clients get up to 2 s to read the report, or with --serve-hold up to S
  // for one to have read the whole run.
  std::unique_ptr<ServedPage> page;
  if (!a.serve.empty()) {
    page = std::make_unique<ServedPage>();
    page->listen("vines hil", a.serve);
  }
  const host::HilReport r = host::run_hil(scene, a.opt, page ? page->watch() : nullptr);
  if (page)
    page->stop(a.serve_hold_s > 0 ? std::chrono::milliseconds(std::llround(1e3 * a.serve_hold_s))
                                  : std::chrono::milliseconds(2000),
               a.serve_hold_s > 0);
  if (a.as_json) std::printf("%s\n", host::to_json(r).dump().c_str());
  else print_hil(r);
  // After the report, so that a run refused as a baseline is still seen.
  std::fflush(stdout);
  if (!a.opt.commission_path.empty() && r.twin && r.twin->estimator != "none")
    host::commission_twin(a.opt.commission_path, host::twin_building(scene, a.opt), *r.twin, scene.record.path);
  if (!r.outputs_finite) return kRefused;
  // A fault kind not survived: the run finished, its results are degraded.
  if (!r.survived) {
    std::string kinds;
    for (const auto& [name, c] : r.faults)
      if (!c.ok) kinds += (kinds.empty() ? "" : ", ") + name;
    std::fflush(stdout);
    std::fprintf(stderr, "vines hil: not survived: %s\n", kinds.c_str());
  }
  return finished_status(!r.survived, a.accept_degraded);
}

// What each fault option injects at the samples SPEC picks.
const char* fault_help(host::FaultKind k) {
  using host::FaultKind;
  switch (k) {
    case FaultKind::kDrop: return "sample frames not sent";
    case FaultKind::kCorrupt: return "a byte of the sample frame flipped";
    case FaultKind::kDuplicate: return "sample frames sent twice";
    case FaultKind::kReorder: return "a sample frame sent after the next one";
    case FaultKind::kLate: return "samples sent --late-periods periods late";
    case FaultKind::kNonFinite: return "NaN or inf samples";
    case FaultKind::kStall: return "the link silent for --stall-periods periods, their samples sent after";
    case FaultKind::kRestart: return "kill the node, start a new one";
    default: return "";
  }
}

}  // namespace

void add_hil(CLI::App& vines) {
  using host::FaultKind;
  auto a = std::make_shared<HilArgs>();
  host::HilOptions& opt = a->opt;
  CLI::App* cmd = add_command(
      vines, "hil",
      "Hardware-in-the-loop bench: streams the scene's record at its sensor rate to the firmware node (`vines node` "
      "as a child process, over pipes, protocol in docs/link_protocol.md), injects faults, checks deadlines and "
      "reports steps, deadline misses, latency, faults injected/detected/survived and the largest deviation of the "
      "telemetry from the offline run (bit for bit equal without faults); digital-twin monitor and shake-table "
      "(hybrid) modes.",
      "SPEC of a fault: a rate per sample from 0 to 1 (the probability that a sample is hit; 1: every sample after "
      "the first; a sample drawn for several kinds takes the first in the order listed), or @K1,K2,... sample "
      "indices. Each fault kind is reported survived or not: outputs finite and, after each fault's recovery "
      "window, the top floor's deviation from the clean run within the clean run's peak (docs/link_protocol.md). Exit 0; 3 if a "
      "kind was not survived; 1 if outputs were not finite or the node failed.",
      [a] { return hil(*a); });
  a->cmd = cmd;
  cmd->add_option("SCENE.toml", a->scene_path, "scene file (see data/scenes/README.md)")->required();
  const std::vector<std::string> modes(std::begin(host::kHilModeNames), std::end(host::kHilModeNames));
  cmd->add_option_function<std::string>(
         "--mode",
         [&opt, modes](const std::string& v) {
           opt.mode = static_cast<host::HilMode>(std::find(modes.begin(), modes.end(), v) - modes.begin());
         },
         "replay (default), twin (digital-twin monitor), hybrid (shake table)")
      ->type_name("replay|twin|hybrid")
      ->check(CLI::IsMember(modes));
  cmd->add_flag("--realtime,!--virtual-clock", opt.realtime,
                "pace samples at the sensor rate on the wall clock; or (default) lock step, as fast as the link "
                "allows (the node's clock is the samples' stamps)");
  cmd->add_option("--duration", opt.duration_s, "first S seconds of the record only")
      ->type_name("S")
      ->check(number_in(1e-6, 1e6));
  cmd->add_flag("--json", a->as_json, "print one JSON object");
  add_serve(*cmd, &a->serve,
            "serve the monitoring page while the bench runs; ADDRESS: [HOST:]PORT (HOST 127.0.0.1 unless given; "
            "PORT 0: any free one); read-only, at most 4 clients (docs/hil.md)");
  cmd->add_option("--serve-hold", a->serve_hold_s,
                  "after the run, keep the page up to S seconds for a client to read the whole run (a run in lock "
                  "step may end before a browser opens the page; default: the clients then connected get 2 s)")
      ->type_name("S")
      ->check(number_in(1e-3, 1e6));
  add_accept_degraded(*cmd, &a->accept_degraded);
  cmd->add_option("--csv", opt.csv, "one row per step (and FILE.json beside it: the run, for vines view)")->type_name("FILE")->check(non_empty_path());
  add_number_list(*cmd, "--floors", &opt.floors, 1, 1000,
                  "floors whose displacement --csv (x_F_m) and the page (--serve) add, 1-based, comma-separated "
                  "(the top floor's is always there)")
      ->type_name("F1,F2,...");
  cmd->add_option("--timeout", opt.timeout_s, "longest wait for the node (default 5, 60 with QEMU)")
      ->type_name("S")
      ->check(number_in(0.01, 3600));
  cmd->add_option("--deadline", opt.deadline_periods, "telemetry due P sensor periods after its sample (default 1)")
      ->type_name("PERIODS")
      ->check(number_in(0.01, 1e6));
  cmd->add_option_function<std::string>(
         "--node",
         [&opt](const std::string& v) {
           const std::vector<std::string> names = host::node_names();
           if (std::find(names.begin(), names.end(), v) != names.end()) {
             opt.node = v;
           } else if (host::is_tcp(v) || host::is_serial(v)) {
             try {
               if (host::is_tcp(v)) host::parse_tcp_address(v, "", false);
               else host::parse_serial_address(v);
             } catch (const std::runtime_error& e) {
               throw CLI::ValidationError("--node", e.what());
             }
             opt.node = v;
           } else if (v.rfind("qemu:", 0) == 0) {
             throw CLI::ValidationError("--node", v + ": not a node (" + host::node_list() + ", or a program's path)");
           } else {
             opt.node_command = v;
           }
         },
         host::node_list() + " (default host: `vines node`; qemu:TARGET: the board image in QEMU, in the "
         "board's scalar, instructions counted; build the preset first), tcp:HOST:PORT (a node that `vines node "
         "--listen` runs, here or on another machine), serial:DEVICE[@BAUD] (a node on a serial line, raw 8N1, "
         "default 3000000 baud; the bench checks the line carries the run's frames at the sensor rate), or the path "
         "of a node program")
      ->type_name("N");
  cmd->add_option("--image", opt.image,
                  "the board image to run (default: build/TARGET/firmware/app/vines_node_DEVICE.elf; in twin mode with "
                  "the estimator, vines_node_twin.elf)")
      ->type_name("ELF");
  cmd->add_option("--budget-ticks", opt.budget_ticks,
                  "the node's deadline budget in its counter ticks (ns on the host, 25 MHz on a board; default one "
                  "sensor period): overruns reported")
      ->type_name("T")
      ->check(number_in(1, 4e9));
  cmd->add_option("--realtime-priority", opt.rt_priority,
                  "with --realtime: the bench and the host node at SCHED_FIFO priority N with their memory locked "
                  "(mlockall); the report says what the OS granted and what it refused (privilege: root, "
                  "CAP_SYS_NICE, or rtprio in /etc/security/limits.conf)")
      ->type_name("N")
      ->check(CLI::Range(1, 99));
  add_number_list(*cmd, "--cpus", &opt.cpus, 0, 1023,
                  "with --realtime: the bench pinned to core B, the host node to core N")
      ->type_name("B[,N]");

  const std::string faults = "fault options";
  for (int f = 0; f < host::kFaultKinds; ++f) {
    const auto kind = static_cast<FaultKind>(f);
    if (kind == FaultKind::kSaturate) continue;  // a sensor range, not a SPEC
    const std::string name = std::string("--") + host::fault_kind_name(kind);
    cmd->add_option_function<std::string>(
           name,
           [&opt, f, name](const std::string& v) {
             try {
               opt.faults[f] = host::parse_fault_spec(name, v);
             } catch (const std::exception& e) {
               throw CLI::ValidationError(e.what(), CLI::ExitCodes::ValidationError);
             }
           },
           fault_help(kind))
        ->type_name("SPEC")
        ->group(faults);
  }
  cmd->add_option("--late-periods", opt.late_periods, "how late --late sends (default 3)")
      ->type_name("L")
      ->check(number_in(1, 1e5))
      ->group(faults);
  cmd->add_option("--stall-periods", opt.stall_periods, "how long --stall lasts (default 20)")
      ->type_name("S")
      ->check(number_in(1, 1e5))
      ->group(faults);
  cmd->add_option("--saturate", opt.saturate_g, "sensor range [g]")
      ->type_name("G")
      ->check(number_in(1e-6, 100))
      ->group(faults);
  cmd->add_option("--seed", opt.seed, "draws of the rates (default 1)")
      ->type_name("N")
      ->check(number_in(0, 1e15))
      ->group(faults);
  cmd->add_option("--grace", opt.grace_periods, "node: a missing sample held after P periods (default 1.5)")
      ->type_name("P")
      ->check(number_in(0.5, 1000))
      ->group(faults);
  cmd->add_option("--node-stall", opt.node_stall_periods,
                  "node: stall reported after P periods (default 10); also each fault's recovery window before "
                  "survival is judged")
      ->type_name("P")
      ->check(number_in(1, 1e6))
      ->group(faults);

  const std::string twin = kTwinGroup;
  const std::vector<std::string> estimators(std::begin(host::kHilEstimatorNames), std::end(host::kHilEstimatorNames));
  cmd->add_option_function<std::string>(
         "--estimator",
         [&opt, estimators](const std::string& v) {
           opt.estimator =
               static_cast<host::HilEstimator>(std::find(estimators.begin(), estimators.end(), v) - estimators.begin());
         },
         "kalman (default: the node keeps the frame's state on the measured floors, identifies each story's "
         "stiffness and decides on damage, docs/twin.md) or none (the scene's model run open loop)")
      ->type_name("kalman|none")
      ->check(CLI::IsMember(estimators))
      ->group(twin);
  cmd->add_option("--truth", opt.truth_path,
                  "the measured building's scene (default: SCENE itself): same story count, sensor rate and record; "
                  "its own frame (frame.stiffness_scales for a damaged story), device and initial state")
      ->type_name("TRUTH.toml")
      ->check(non_empty_path())
      ->group(twin);
  cmd->add_option("--baseline", opt.baseline_path,
                  "the healthy building's baseline that --commission runs wrote: the decision tests the change "
                  "from it (default: from the nominal scene, the healthy stories and masses within "
                  "--twin-healthy-tolerance and --twin-mass-tolerance of it)")
      ->type_name("FILE")
      ->check(non_empty_path())
      ->group(twin);
  cmd->add_option("--commission", opt.commission_path,
                  "the run is on the healthy building: add its identified stories to this baseline file "
                  "(created if missing; one run per healthy record; a run whose report has a caveat is refused, exit 1)")
      ->type_name("FILE")
      ->check(non_empty_path())
      ->group(twin);
  cmd->add_option("--truth-stiffness-scale", opt.truth_stiffness_scale,
                  "the measured building's eta_k, times the truth scene's (default 1)")
      ->type_name("ETA")
      ->check(number_in(0.01, 10))
      ->group(twin);
  add_number_list(*cmd, "--sensors", &opt.sensors, 0, 1000,
                  "floor accelerometers, 1-based, comma-separated (default: the top floor; at most 8); the ground "
                  "accelerometer is the node's input")
      ->type_name("F1,F2,...")
      ->group(twin);
  cmd->add_option("--measure-noise", opt.measure_noise_mps2, "sensor noise (m/s^2 RMS, default 0)")
      ->type_name("A")
      ->check(number_in(0, 1e3))
      ->group(twin);
  cmd->add_option("--measure-noise-pct", opt.measure_noise_pct, "sensor noise as % of each channel's RMS")
      ->type_name("P")
      ->check(number_in(0, 1e3))
      ->group(twin);
  cmd->add_option("--measure-bias", opt.measure_bias_mps2,
                  "each sensor's constant bias, drawn from N(0, B^2) (m/s^2, default 0)")
      ->type_name("B")
      ->check(number_in(0, 1e3))
      ->group(twin);
  cmd->add_option("--adc-lsb", opt.adc_lsb_mps2, "ADC resolution: readings rounded to it (m/s^2, default 0: none)")
      ->type_name("Q")
      ->check(number_in(0, 1e3))
      ->group(twin);
  cmd->add_option("--drift-limit", opt.drift_limit_m, "drift alarm, every story (m; default 0: none)")
      ->type_name("M")
      ->check(number_in(0, 1e3))
      ->group(twin);
  cmd->add_option("--residual-limit", opt.residual_limit_mps2, "RMS residual alarm threshold (default 0.05 m/s^2)")
      ->type_name("A")
      ->check(number_in(0, 1e3))
      ->group(twin);
  cmd->add_option("--residual-window", opt.residual_window_s, "window of the RMS residual (s, default 1)")
      ->type_name("S")
      ->check(number_in(1e-6, 1e6))
      ->group(twin);

  // The estimator's tuning (docs/twin.md section 4): defaults from there.
  const std::string tuning = kTuningGroup;
  host::TwinTuning& tu = opt.tuning;
  const std::pair<const char*, std::pair<double*, const char*>> knobs[] = {
      {"--twin-model-sd", {&tu.model_accel_sd, "process noise: floor acceleration the model misses [m/s^2]"}},
      {"--twin-force-sd", {&tu.force_sd_mps2, "VI NES force over its floor's mass, sd [m/s^2]"}},
      {"--twin-force-tau", {&tu.force_tau_s, "its correlation time [s]"}},
      {"--twin-quiet-share", {&tu.quiet_force_share, "the force's sd between impacts, a share of --twin-force-sd"}},
      {"--twin-jump-sigma", {&tu.jump_sigma, "an innovation beyond this many sd is an impact..."}},
      {"--twin-jump-hold", {&tu.jump_hold_s, "...whose gain is held this long [s]"}},
      {"--twin-memory", {&tu.memory_s, "the losses' memory [s]"}},
      {"--twin-prior-sd", {&tu.prior_sd, "prior sd of each loss"}},
      {"--twin-max-step", {&tu.max_step, "largest change of a loss in one update"}},
      {"--twin-kappa", {&tu.kappa, "the TMD spring's alarm: |loss| beyond this many sd..."}},
      {"--twin-device-loss-min", {&tu.device_loss_min, "...and beyond this |loss|"}},
      {"--twin-hold", {&tu.hold_s, "an alarm's candidate held this long [s]"}},
      {"--twin-threshold", {&tu.threshold, "damage: one-story statistic of the absolute test"}},
      {"--twin-threshold-change", {&tu.threshold_change, "...of a change test (damage during the record)"}},
      {"--twin-two-story", {&tu.two_story, "two stories: the pair's statistic beyond the best story's by this"}},
      {"--twin-two-share", {&tu.two_story_share, "...and by this share of the best story's statistic"}},
      {"--twin-separation", {&tu.separation, "a story named: its statistic beyond the next story's by this"}},
      {"--twin-inflation", {&tu.inflation, "the estimate's covariance times this in the tests"}},
      {"--twin-drift-sd", {&tu.drift_sd, "a change test's model drift per story"}},
      {"--twin-calm", {&tu.calm_s, "a change test leaves out this long after each VI NES impact [s]"}},
      {"--twin-before-sd", {&tu.before_sd_max, "a candidate onset: every story's fit before it within this sd"}},
      {"--twin-score-window", {&tu.score_window_s, "the change score's memory [s]"}},
      {"--twin-misfit-level", {&tu.misfit_level, "the change score per parameter of a model that holds; beyond "
                                                 "it, the absolute test's estimate covariance times the excess..."}},
      {"--twin-misfit-memory", {&tu.misfit_memory_s, "...held this long [s]"}},
      {"--twin-fit-tail", {&tu.fit_tail, "the absolute test's best hypothesis leaves unexplained at most the "
                                         "chi-square quantile of this tail (below 1)"}},
      {"--twin-suspect", {&tu.suspect, "the change score beyond this restarts the losses' information..."}},
      {"--twin-restart-gap", {&tu.restart_gap_s, "...at most once in this long [s]..."}},
      {"--twin-restart-keep", {&tu.restart_keep, "...keeping this share of it"}},
      {"--twin-healthy-tolerance", {&tu.healthy_tolerance, "no baseline: the healthy stories within this of the drawing"}},
      {"--twin-mass-tolerance", {&tu.mass_tolerance, "no baseline: the floors' masses within this of the drawing"}},
  };
  for (const auto& [name, k] : knobs)
    cmd->add_option(name, *k.first, k.second)->type_name("X")->check(number_in(1e-9, 1e6))->group(tuning);

  const std::string hybrid = kHybridGroup;
  cmd->add_option("--actuator-hz", opt.actuator_hz, "natural frequency of the actuator, a second-order servo (Hz, default 20)")
      ->type_name("F")
      ->check(number_in(0.1, 1e4))
      ->group(hybrid);
  cmd->add_option("--actuator-zeta", opt.actuator_zeta, "its damping ratio (default 0.7)")
      ->type_name("Z")
      ->check(number_in(0.01, 10))
      ->group(hybrid);
  cmd->add_option("--actuator-delay", opt.actuator_delay_s, "its pure delay (s, default 0.005)")
      ->type_name("S")
      ->check(number_in(0, 1))
      ->group(hybrid);
  cmd->add_option("--force-noise", opt.force_noise_n, "load cell noise (N, default 50)")
      ->type_name("N")
      ->check(number_in(0, 1e9))
      ->group(hybrid);
  cmd->add_option("--force-lsb", opt.force_lsb_n, "load cell resolution (N, default 10)")
      ->type_name("N")
      ->check(number_in(0, 1e9))
      ->group(hybrid);
  const std::vector<std::string> comps(std::begin(host::kHilCompNames), std::end(host::kHilCompNames));
  cmd->add_option_function<std::string>(
         "--comp",
         [&opt, comps](const std::string& v) {
           opt.comp = static_cast<host::HilComp>(std::find(comps.begin(), comps.end(), v) - comps.begin());
         },
         "the node's compensation of the table's delay: poly (default: polynomial extrapolation over --comp-delay), "
         "adaptive (adaptive time series, ATS: u = a0 x + a1 x' + a2 x'', fitted online to the measured table; a1 "
         "starts at --comp-delay), none")
      ->type_name("poly|adaptive|none")
      ->check(CLI::IsMember(comps))
      ->group(hybrid);
  cmd->add_option("--comp-delay", opt.comp_delay_s, "delay compensated (s; default: delay + 2 zeta/w + h/2, the command held over a period h; 0: none)")
      ->type_name("S")
      ->check(number_in(0, 1))
      ->group(hybrid);
  cmd->add_option("--comp-order", opt.comp_order, "order of the compensation (1-3, default 2)")
      ->type_name("P")
      ->check(number_in(1, 3))
      ->group(hybrid);
  cmd->add_option("--comp-window", opt.comp_window_s,
                  "adaptive: memory of the fit, the time constant of its exponential forgetting (s, default 1)")
      ->type_name("S")
      ->check(number_in(0.05, 100))
      ->group(hybrid);
}

}  // namespace vines::cli
