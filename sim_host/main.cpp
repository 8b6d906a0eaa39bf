// vines: command-line front end of the VI NES firmware model.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>

#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"
#include "sim_host/sweep.hpp"
#include "sim_host/sweep_mpi.hpp"

namespace {

constexpr const char* kUsage =
    "vines - Vibro-Impact Nonlinear Energy Sink firmware model (host build)\n"
    "\n"
    "usage: vines <command> [options]\n"
    "\n"
    "commands:\n"
    "  run SCENE.toml [--record PATH] [--out DIR]\n"
    "      Run a scene (frame, device, contact law, record). With a device, the\n"
    "      bare frame runs on the same record too and x_r, E_r are reported.\n"
    "      Writes DIR/summary.json and DIR/timeseries.csv (default DIR: out/<scene name>).\n"
    "  sweep SPEC.toml [--out DIR] [--threads N] [--no-progress]\n"
    "      Run the grid of scenes a study spec describes (data/studies/*.toml) on all\n"
    "      cores (or MPI ranks: mpirun -n K vines sweep ...); writes DIR/results.csv\n"
    "      and DIR/summary.json (default DIR: out/<spec name>).\n"
    "  help [COMMAND]\n"
    "      This text.\n"
    "\n"
    "Records are looked up as given, next to the scene file, then in\n"
    "$VINES_GROUND_MOTIONS (default: ../shared/data/ground_motions beside the repository).\n";

constexpr const char* kRunUsage =
    "usage: vines run SCENE.toml [--record PATH] [--out DIR] [--quiet]\n"
    "\n"
    "  SCENE.toml     scene file (see data/scenes/README.md)\n"
    "  --record PATH  use this ground-motion file instead of the scene's [record] path\n"
    "                 (same format settings as the scene's [record] table)\n"
    "  --out DIR      output folder (default: out/<scene name>)\n"
    "  --quiet        print nothing but errors\n";

constexpr const char* kSweepUsage =
    "usage: vines sweep SPEC.toml [--out DIR] [--threads N] [--no-progress]\n"
    "\n"
    "  SPEC.toml      study spec (format at the top of sim_host/sweep.hpp and in\n"
    "                 data/studies/README.md)\n"
    "  --out DIR      output folder (default: out/<spec name>)\n"
    "  --threads N    worker threads (default: all cores; per rank under MPI)\n"
    "  --no-progress  no progress bar / lines on stderr\n"
    "Ctrl-C stops after the runs under way and keeps what finished.\n";

int usage_error(const char* usage, const std::string& what) {
  std::fprintf(stderr, "vines: %s\n\n%s", what.c_str(), usage);
  return 2;
}

int cmd_run(const std::vector<std::string>& args) {
  using namespace vines::host;
  std::string scene_path;
  RunOptions opt;
  bool out_given = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kRunUsage, stdout);
      return 0;
    } else if (a == "--record" || a == "--out") {
      if (i + 1 >= args.size()) return usage_error(kRunUsage, a + " needs a value");
      (a == "--record" ? opt.record_override : opt.out_dir) = args[++i];
      out_given |= a == "--out";
    } else if (a == "--quiet") {
      opt.quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      return usage_error(kRunUsage, "unknown option " + a);
    } else if (scene_path.empty()) {
      scene_path = a;
    } else {
      return usage_error(kRunUsage, "more than one scene given");
    }
  }
  if (scene_path.empty()) return usage_error(kRunUsage, "no scene given");
  try {
    const Scene scene = load_scene(scene_path);
    if (!out_given) opt.out_dir = "out/" + scene.name;
    const nlohmann::json j = run_scene(scene, opt);
    if (!opt.quiet) {
      std::printf("scene %s: %s, %d stories, %s, %.0f Hz\n", scene.name.c_str(),
                  j["device"].get<std::string>().c_str(), j["stories"].get<int>(),
                  j["scalar"].get<std::string>().c_str(), j["sensor_rate_hz"].get<double>());
      std::printf("  peak top displacement %.6f m at t = %.3f s\n",
                  j["peak_top_displacement_m"].get<double>(), j["t_peak_top_s"].get<double>());
      if (j.contains("x_r"))
        std::printf("  x_r = %.2f %%   E_r = %.2f %%   (bare peak %.6f m)\n", 100 * j["x_r"].get<double>(),
                    100 * j["E_r"].get<double>(), j["bare"]["peak_top_displacement_m"].get<double>());
      if (j["device"] == "vines")
        std::printf("  contacts %lld, deepest overlap %.3f mm, contact sub-steps %lld\n",
                    j["contacts"].get<long long>(), 1e3 * j["max_overlap_m"].get<double>(),
                    j["counters"]["contact_substeps"].get<long long>());
      if (!j["energy_balance_residual"].is_null())
        std::printf("  energy balance residual %.2e (relative)\n", j["energy_balance_residual"].get<double>());
      std::printf("  loop wall time %.2f ms; results in %s/\n", 1e3 * j["wall_time_s"].get<double>(),
                  opt.out_dir.c_str());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vines run: %s\n", e.what());
    return 1;
  }
}

std::atomic<bool> g_stop{false};

int cmd_sweep(const std::vector<std::string>& args) {
  using namespace vines::host;
  std::string spec_path;
  SweepOptions opt;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kSweepUsage, stdout);
      return 0;
    } else if (a == "--out" || a == "--threads") {
      if (i + 1 >= args.size()) return usage_error(kSweepUsage, a + " needs a value");
      const std::string& v = args[++i];
      if (a == "--out") {
        opt.out_dir = v;
      } else {
        char* end = nullptr;
        const long n = std::strtol(v.c_str(), &end, 10);
        if (*end != '\0' || n < 1 || n > 1024) return usage_error(kSweepUsage, "--threads takes 1 to 1024");
        opt.threads = static_cast<int>(n);
      }
    } else if (a == "--no-progress") {
      opt.progress = false;
    } else if (!a.empty() && a[0] == '-') {
      return usage_error(kSweepUsage, "unknown option " + a);
    } else if (spec_path.empty()) {
      spec_path = a;
    } else {
      return usage_error(kSweepUsage, "more than one spec given");
    }
  }
  if (spec_path.empty()) return usage_error(kSweepUsage, "no spec given");
  Mpi mpi;
  try {
    const SweepSpec spec = load_sweep(spec_path);
    const std::vector<RunPlan> plan = plan_runs(spec);
    if (opt.out_dir.empty()) opt.out_dir = "out/" + std::filesystem::path(spec_path).stem().string();
    std::signal(SIGINT, [](int) {
      g_stop = true;
      std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends at once
    });
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<RunResult> results = execute(spec, plan, opt.threads, mpi.rank(), mpi.size(), &g_stop,
                                             opt.progress && mpi.rank() == 0);
    mpi.gather(&results);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (mpi.rank() != 0) return 0;
    const nlohmann::json s = write_sweep(spec, plan, results, opt.out_dir, wall);
    std::printf("sweep %s: %zu of %zu runs in %.2f s (%.1f runs/s, %d rank%s), %zu failed; results in %s/\n",
                spec_path.c_str(), s["done"].get<std::size_t>(), plan.size(), wall, s["runs_per_s"].get<double>(),
                mpi.size(), mpi.size() > 1 ? "s" : "", s["failed"].get<std::size_t>(), opt.out_dir.c_str());
    for (const auto& st : s["studies"]) {
      if (st["x_r"].is_null()) continue;
      std::printf("  %-24s %-5s n=%-5zu x_r %6.2f %% +- %5.2f [%6.2f, %6.2f]  E_r %6.2f %% +- %5.2f",
                  st["name"].get<std::string>().c_str(), st["device"].get<std::string>().c_str(),
                  st["runs"].get<std::size_t>(), 100 * st["x_r"]["mean"].get<double>(),
                  100 * st["x_r"]["sd"].get<double>(), 100 * st["x_r"]["min"].get<double>(),
                  100 * st["x_r"]["max"].get<double>(), 100 * st["E_r"]["mean"].get<double>(),
                  100 * st["E_r"]["sd"].get<double>());
      if (st.contains("best"))
        std::printf("  best %s = %g", st["best"]["key"].get<std::string>().c_str(), st["best"]["value"].get<double>());
      std::printf("\n");
    }
    if (g_stop) {
      std::fprintf(stderr, "vines sweep: interrupted; kept the %zu finished runs\n", s["done"].get<std::size_t>());
      return 130;
    }
    return s["failed"].get<std::size_t>() == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vines sweep: %s\n", e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) return usage_error(kUsage, "no command given");
  const std::string cmd = args.front();
  args.erase(args.begin());
  if (cmd == "run") return cmd_run(args);
  if (cmd == "sweep") return cmd_sweep(args);
  if (cmd == "help" || cmd == "-h" || cmd == "--help") {
    if (!args.empty() && args[0] == "run") std::fputs(kRunUsage, stdout);
    else if (!args.empty() && args[0] == "sweep") std::fputs(kSweepUsage, stdout);
    else std::fputs(kUsage, stdout);
    return 0;
  }
  return usage_error(kUsage, "unknown command '" + cmd + "'");
}
