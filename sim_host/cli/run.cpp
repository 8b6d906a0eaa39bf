// `vines run SCENE.toml`: one scene (and its bare frame), summary.json and timeseries.csv.
#include <cstdio>
#include <memory>
#include <string>

#include "sim_host/cli/cli.hpp"
#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"

namespace vines::cli {
namespace {

struct RunArgs {
  std::string scene_path;
  host::RunOptions opt;
  const CLI::Option* out = nullptr;  // --out, given (even empty: write nothing) or not
};

int run(RunArgs a) {
  using namespace vines::host;
  RunOptions& opt = a.opt;
  const Scene scene = load_scene(a.scene_path);
  if (a.out->count() == 0) opt.out_dir = "out/" + scene.name;
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
  // Limits the loop ran into are reported, never silent (even with --quiet).
  const auto& k = j["counters"];
  const vines::LoopParams& loop = scene.params.loop;
  if (k["substep_cap_hits"].get<long long>() > 0 && loop.contact_scheme == vines::ContactScheme::kAdaptive)
    std::fprintf(stderr, "vines run: warning: %lld steps hit the sub-step cap (loop.max_substeps_per_step = %d): "
                 "contacts in them are not resolved\n",
                 k["substep_cap_hits"].get<long long>(), loop.max_substeps_per_step);
  if (k["substep_cap_hits"].get<long long>() > 0 && loop.contact_scheme == vines::ContactScheme::kBounded)
    std::fprintf(stderr, "vines run: warning: in %lld steps the sub-step budget (loop.bounded_substeps = %d) "
                 "could not follow every event: they were deferred to the next step or stepped over\n",
                 k["substep_cap_hits"].get<long long>(), loop.bounded_substeps);
  if (k["divergences_rolled_back"].get<long long>() + k["bad_samples_held"].get<long long>() > 0)
    std::fprintf(stderr, "vines run: warning: %lld diverging steps rolled back, %lld non-finite samples held\n",
                 k["divergences_rolled_back"].get<long long>(), k["bad_samples_held"].get<long long>());
  return kOk;
}

}  // namespace

void add_run(CLI::App& vines) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* cmd = add_command(vines, "run",
                              "Run a scene (frame, device, contact law, record). With a device, the bare frame runs "
                              "on the same record too and x_r, E_r are reported. Writes DIR/summary.json and "
                              "DIR/timeseries.csv.",
                              "", [a] { return run(*a); });
  cmd->add_option("SCENE.toml", a->scene_path, "scene file (see data/scenes/README.md)")->required();
  cmd->add_option("--record", a->opt.record_override,
                  "use this ground-motion file instead of the scene's [record] path (format read from the file: "
                  "PEER AT2 or columns; the scene's units, column and scale apply to columns)")
      ->type_name("PATH");
  a->out = cmd->add_option("--out", a->opt.out_dir, "output folder (default: out/<scene name>)")->type_name("DIR");
  cmd->add_flag("--quiet", a->opt.quiet, "print nothing but errors");
}

}  // namespace vines::cli
