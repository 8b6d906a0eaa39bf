// `vines run SCENE.toml`: one scene (and its bare frame), summary.json and timeseries.csv.
#include <cstdio>
#include <memory>
#include <string>

#include "sim_host/cli/cli.hpp"
#include "sim_host/names.hpp"
#include "sim_host/output.hpp"
#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"

namespace vines::cli {
namespace {

struct RunArgs {
  std::string scene_path;
  host::RunOptions opt;
  const CLI::Option* out = nullptr;  // --out, given or not
};

int run(RunArgs a) {
  using namespace vines::host;
  RunOptions& opt = a.opt;
  const Scene scene = load_scene(a.scene_path);
  if (a.out->count() == 0) opt.out_dir = "out/" + safe_file_name(scene.name);
  const RunReport r = run_scene(scene, opt);
  const vines::SceneParams& p = scene.params;
  const Counters& k = r.totals.count;
  if (!opt.quiet) {
    std::printf("scene %s: %s, %d stories, %s, %.0f Hz\n", scene.name.c_str(), device_name(p.device.kind),
                r.info.stories, scalar_name(r.scalar), p.loop.sensor_rate_hz);
    std::printf("  peak top displacement %.6f m at t = %.3f s\n", r.totals.peak_top, r.totals.t_peak_top);
    if (r.bare)
      std::printf("  x_r = %.2f %%   E_r = %.2f %%   (bare peak %.6f m)\n", 100 * r.x_r(), 100 * r.E_r(),
                  r.bare->peak_top);
    if (p.device.kind == vines::DeviceKind::kVines)
      std::printf("  contacts %lld, deepest overlap %.3f mm, contact sub-steps %lld\n",
                  static_cast<long long>(k.contacts), 1e3 * r.totals.max_overlap,
                  static_cast<long long>(k.contact_substeps));
    if (p.loop.energy_ledger)
      std::printf("  energy balance residual %.2e (relative)\n", r.totals.ledger.relative_residual());
    std::printf("  loop wall time %.2f ms; results in %s/\n", 1e3 * r.wall_s, opt.out_dir.c_str());
  }
  // Limits the loop ran into are reported, never silent (even with --quiet).
  const vines::LoopParams& loop = p.loop;
  const auto cap_hits = static_cast<long long>(k.cap_hits);
  if (cap_hits > 0 && loop.contact_scheme == vines::ContactScheme::kAdaptive)
    std::fprintf(stderr, "vines run: warning: %lld steps hit the sub-step cap (loop.max_substeps_per_step = %d): "
                 "contacts in them are not resolved\n",
                 cap_hits, loop.max_substeps_per_step);
  if (cap_hits > 0 && loop.contact_scheme == vines::ContactScheme::kBounded)
    std::fprintf(stderr, "vines run: warning: in %lld steps the sub-step budget (loop.bounded_substeps = %d) "
                 "could not follow every event: they were deferred to the next step or stepped over\n",
                 cap_hits, loop.bounded_substeps);
  if (k.divergences + k.bad_samples > 0)
    std::fprintf(stderr, "vines run: warning: %lld diverging steps rolled back, %lld non-finite samples held\n",
                 static_cast<long long>(k.divergences), static_cast<long long>(k.bad_samples));
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
  a->out = cmd->add_option("--out", a->opt.out_dir,
                           "output folder: new, empty or vines run's own; its files this run does not write are "
                           "removed (default: out/<scene name>)")
               ->type_name("DIR")
               ->check(non_empty_path());
  cmd->add_flag("--quiet", a->opt.quiet, "print nothing but errors");
}

}  // namespace vines::cli
