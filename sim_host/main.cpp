// vines: command-line front end of the VI NES firmware model.
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include "sim_host/cli/cli.hpp"
#include "sim_host/bench.hpp"
#include "sim_host/design.hpp"
#include "sim_host/engine.hpp"
#include "sim_host/hil.hpp"
#include "sim_host/names.hpp"
#include "sim_host/reference/report.hpp"
#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"
#include "sim_host/stress.hpp"
#include "sim_host/sweep.hpp"
#include "sim_host/sweep_mpi.hpp"
#include "vines/model_image.hpp"

namespace {

constexpr const char* kHilUsage =
    "usage: vines hil SCENE.toml [--mode replay|twin|hybrid] [--realtime | --virtual-clock]\n"
    "                 [--duration S] [--json] [--csv FILE] [--timeout S] [--deadline PERIODS]\n"
    "                 [fault options] [twin options] [hybrid options]\n"
    "\n"
    "  Streams the scene's record at its sensor rate to the firmware node (`vines node`\n"
    "  as a child process, over pipes, protocol in docs/link_protocol.md) and reports\n"
    "  steps, deadline misses, latency, faults injected/detected/survived and the largest\n"
    "  deviation of the telemetry from the offline run (bit for bit equal without faults).\n"
    "  --mode M          replay (default), twin (digital-twin monitor), hybrid (shake table)\n"
    "  --realtime        pace samples at the sensor rate on the wall clock; default\n"
    "  --virtual-clock   lock step, as fast as the link allows (the node's clock is the\n"
    "                    samples' stamps)\n"
    "  --duration S      first S seconds of the record only\n"
    "  --json            print one JSON object; --csv FILE: one row per step\n"
    "  --timeout S       longest wait for the node (default 5, 60 with QEMU); --deadline P:\n"
    "                    telemetry due P sensor periods after its sample (default 1)\n"
    "  --node N          host (default: `vines node`), qemu:cortex-m4f or qemu:cortex-m7 (the\n"
    "                    board image in QEMU, float / double, instructions counted; build\n"
    "                    the preset first), or the path of a node program\n"
    "  --image ELF       the board image to run (default: build/TARGET/firmware/app/\n"
    "                    vines_node_DEVICE.elf)\n"
    "  --budget-ticks T  the node's deadline budget in its counter ticks (ns on the host,\n"
    "                    25 MHz on a board; default one sensor period): overruns reported\n"
    "fault options (SPEC: a rate per sample from 0 to 1, or @K1,K2,... sample indices):\n"
    "  --drop SPEC  --corrupt SPEC  --duplicate SPEC  --reorder SPEC  --nonfinite SPEC\n"
    "  --late SPEC [--late-periods L (3)]   --stall SPEC [--stall-periods S (20)]\n"
    "  --restart SPEC (kill the node, start a new one)   --saturate G (sensor range [g])\n"
    "  --seed N (draws of the rates, default 1)  --grace P (node: missing sample held after\n"
    "  P periods, default 1.5)  --node-stall P (node: stall reported after P periods, 10)\n"
    "twin options: --truth-stiffness-scale ETA (the measured building's eta_k, default 1)\n"
    "  --measure-noise A (m/s^2 RMS)  --drift-limit M (every story, 0: none)\n"
    "  --residual-limit A (RMS alarm threshold, default 0.05 m/s^2)  --residual-window S (1)\n"
    "hybrid options: --actuator-hz F (20) --actuator-zeta Z (0.7) --actuator-delay S (0.005)\n"
    "  --force-noise N (50) --force-lsb N (10) --comp-delay S (default: delay + 2 zeta/w;\n"
    "  0: no compensation) --comp-order P (1-3, default 2)\n";

int usage_error(const char* usage, const std::string& what) {
  std::fprintf(stderr, "vines: %s\n\n%s", what.c_str(), usage);
  return 2;
}

// One line of the hil report.
void print_hil(const nlohmann::json& j) {
  std::printf("hil %s: %s mode, %s clock, %s, %.0f Hz, node %s\n", j["scene"].get<std::string>().c_str(),
              j["mode"].get<std::string>().c_str(), j["clock"].get<std::string>().c_str(),
              j["scalar"].get<std::string>().c_str(), j["sensor_rate_hz"].get<double>(),
              j["node"].get<std::string>().c_str());
  const auto& nd = j["node_deadline"];
  std::printf("  node deadline monitor: %lld overruns of a %lld-tick budget, worst step %lld ticks (k %lld)",
              nd["overruns"].get<long long>(), nd["budget_ticks"].get<long long>(), nd["worst_ticks"].get<long long>(),
              nd["worst_k"].get<long long>());
  if (j.contains("worst_step_instructions"))
    std::printf("; %.0f instructions (median %.0f)", j["worst_step_instructions"].get<double>(),
                j["median_step_instructions"].get<double>());
  if (nd["stack_peak_bytes"].get<long long>() > 0) std::printf("; stack %lld B", nd["stack_peak_bytes"].get<long long>());
  std::printf("\n");
  std::printf("  steps %lld of %lld, deadline misses %lld (deadline %.3g ms)", j["steps"].get<long long>(),
              j["samples"].get<long long>(), j["deadline_misses"].get<long long>(), 1e3 * j["deadline_s"].get<double>());
  if (!j["latency_us"].is_null())
    std::printf(", latency mean %.0f us, p99 %.0f us, max %.0f us", j["latency_us"]["mean"].get<double>(),
                j["latency_us"]["p99"].get<double>(), j["latency_us"]["max"].get<double>());
  std::printf("\n  faults injected %lld, detected %lld, survived %lld; node restarts %lld\n",
              j["faults_injected"].get<long long>(), j["faults_detected"].get<long long>(),
              j["faults_survived"].get<long long>(), j["node_restarts"].get<long long>());
  for (const auto& [name, c] : j["faults"].items())
    std::printf("    %-10s injected %5lld  detected %5lld  survived %5lld\n", name.c_str(), c["injected"].get<long long>(),
                c["detected"].get<long long>(), c["survived"].get<long long>());
  std::printf("  max deviation from offline %.3g m%s; outputs finite: %s\n", j["max_deviation_from_offline"].get<double>(),
              j["bit_exact"].get<bool>() ? " (bit for bit equal)" : "", j["outputs_finite"].get<bool>() ? "yes" : "NO");
  if (j.contains("twin")) {
    const auto& t = j["twin"];
    std::printf("  twin: eta_k %.3g, residual RMS %.4g m/s^2 (max %.4g), residual alarm %lld steps", 
                t["truth_stiffness_scale"].get<double>(), t["residual_rms_mps2"].get<double>(),
                t["residual_max_mps2"].get<double>(), t["residual_alarm_steps"].get<long long>());
    if (!t["first_residual_alarm_s"].is_null()) std::printf(" from %.2f s", t["first_residual_alarm_s"].get<double>());
    std::printf(", drift alarm %lld steps\n", t["drift_alarm_steps"].get<long long>());
  }
  if (j.contains("hybrid")) {
    const auto& hy = j["hybrid"];
    std::printf("  hybrid: compensation %.2f ms (order %d): tracking RMS %.3g mm, peak %.3g mm; top floor vs pure "
                "simulation RMS %.3g mm, peak %.3g mm (peaks %.4f / %.4f m)\n",
                1e3 * hy["compensation_delay_s"].get<double>(), hy["compensation_order"].get<int>(),
                1e3 * hy["tracking_rms_m"].get<double>(), 1e3 * hy["tracking_peak_m"].get<double>(),
                1e3 * hy["top_diff_from_pure_rms_m"].get<double>(), 1e3 * hy["top_diff_from_pure_peak_m"].get<double>(),
                hy["peak_top_hybrid_m"].get<double>(), hy["peak_top_pure_m"].get<double>());
  }
}

int cmd_hil(const std::vector<std::string>& args) {
  using namespace vines::host;
  std::string scene_path;
  HilOptions opt;
  bool as_json = false;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&]() -> const std::string& {
        if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
        return args[++i];
      };
      auto number = [&](double lo, double hi) {
        const std::string& v = value();
        char* end = nullptr;
        const double x = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !(x >= lo && x <= hi))
          throw std::invalid_argument(a + " takes a number from " + std::to_string(lo) + " to " + std::to_string(hi) +
                                      ", got " + v);
        return x;
      };
      int kind = -1;
      for (int f = 0; f < kFaultKinds; ++f)
        if (a == std::string("--") + fault_kind_name(static_cast<FaultKind>(f))) kind = f;
      if (a == "-h" || a == "--help") {
        std::fputs(kHilUsage, stdout);
        return 0;
      } else if (kind >= 0 && a != "--saturate") {
        opt.faults[kind] = parse_fault_spec(a, value());
      } else if (a == "--saturate") opt.saturate_g = number(1e-6, 100);
      else if (a == "--json") as_json = true;
      else if (a == "--realtime") opt.realtime = true;
      else if (a == "--virtual-clock") opt.realtime = false;
      else if (a == "--mode") opt.mode = value();
      else if (a == "--csv") opt.csv = value();
      else if (a == "--node") {
        const std::string& v = value();
        if (v == "host" || v.rfind("qemu:", 0) == 0) opt.node = v;
        else opt.node_command = v;
      } else if (a == "--image") opt.image = value();
      else if (a == "--budget-ticks") opt.budget_ticks = static_cast<std::uint32_t>(number(1, 4e9));
      else if (a == "--duration") opt.duration_s = number(1e-6, 1e6);
      else if (a == "--timeout") opt.timeout_s = number(0.01, 3600);
      else if (a == "--deadline") opt.deadline_periods = number(0.01, 1e6);
      else if (a == "--seed") opt.seed = static_cast<unsigned long long>(number(0, 1e15));
      else if (a == "--late-periods") opt.late_periods = static_cast<int>(number(1, 1e5));
      else if (a == "--stall-periods") opt.stall_periods = static_cast<int>(number(1, 1e5));
      else if (a == "--grace") opt.grace_periods = number(0.5, 1000);
      else if (a == "--node-stall") opt.node_stall_periods = number(1, 1e6);
      else if (a == "--truth-stiffness-scale") opt.truth_stiffness_scale = number(0.01, 10);
      else if (a == "--measure-noise") opt.measure_noise_mps2 = number(0, 1e3);
      else if (a == "--drift-limit") opt.drift_limit_m = number(0, 1e3);
      else if (a == "--residual-limit") opt.residual_limit_mps2 = number(0, 1e3);
      else if (a == "--residual-window") opt.residual_window_s = number(1e-6, 1e6);
      else if (a == "--actuator-hz") opt.actuator_hz = number(0.1, 1e4);
      else if (a == "--actuator-zeta") opt.actuator_zeta = number(0.01, 10);
      else if (a == "--actuator-delay") opt.actuator_delay_s = number(0, 1);
      else if (a == "--force-noise") opt.force_noise_n = number(0, 1e9);
      else if (a == "--force-lsb") opt.force_lsb_n = number(0, 1e9);
      else if (a == "--comp-delay") opt.comp_delay_s = number(0, 1);
      else if (a == "--comp-order") opt.comp_order = static_cast<int>(number(1, 3));
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else if (scene_path.empty()) scene_path = a;
      else throw std::invalid_argument("more than one scene given");
    }
  } catch (const std::exception& e) {
    return usage_error(kHilUsage, e.what());
  }
  if (scene_path.empty()) return usage_error(kHilUsage, "no scene given");
  try {
    const Scene scene = load_scene(scene_path);
    const nlohmann::json j = run_hil(scene, opt);
    if (as_json) std::printf("%s\n", j.dump().c_str());
    else print_hil(j);
    return j["outputs_finite"].get<bool>() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vines hil: %s\n", e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Commands not yet on CLI11 (sim_host/cli/).
  if (argc > 1) {
    const std::string cmd = argv[1];
    const std::vector<std::string> args(argv + 2, argv + argc);
    if (cmd == "hil") return cmd_hil(args);
    if (cmd == "node") return vines::host::node_main(args);
    if (cmd == "help" && !args.empty()) {
      const char* usage = args[0] == "hil" ? kHilUsage
                        : nullptr;
      if (usage) return std::fputs(usage, stdout), 0;
    }
  }
  using namespace vines::cli;
  CLI::App vines("vines - Vibro-Impact Nonlinear Energy Sink firmware model (host build)", "vines");
  vines.footer("Records are looked up as given, next to the scene file, then in $VINES_GROUND_MOTIONS (default: "
               "../shared/data/ground_motions beside the repository).");
  vines.require_subcommand(1);
  // An option given twice: the last one counts.
  vines.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  use_vines_help(vines);
  add_run(vines);
  add_image(vines);
  add_reference(vines);
  add_sweep(vines);
  add_design(vines);
  add_bench(vines);
  add_stress(vines);
  add_help(vines);
  try {
    vines.parse(argc, argv);
    return kOk;
  } catch (const CLI::RuntimeError& e) {  // a command's own exit status
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    return report_parse_error(vines, e);
  } catch (const std::exception& e) {  // refused input
    std::fprintf(stderr, "vines %s: %s\n", vines.get_subcommands().front()->get_name().c_str(), e.what());
    return kRefused;
  }
}
