// vines: command-line front end of the VI NES firmware model.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"

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

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) return usage_error(kUsage, "no command given");
  const std::string cmd = args.front();
  args.erase(args.begin());
  if (cmd == "run") return cmd_run(args);
  if (cmd == "help" || cmd == "-h" || cmd == "--help") {
    if (!args.empty() && args[0] == "run") std::fputs(kRunUsage, stdout);
    else std::fputs(kUsage, stdout);
    return 0;
  }
  return usage_error(kUsage, "unknown command '" + cmd + "'");
}
