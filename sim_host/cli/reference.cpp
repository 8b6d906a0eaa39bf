// `vines reference SCENE.toml`: the converged reference of a scene (data/reference/).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "sim_host/cli/cli.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/reference/report.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::cli {
namespace {

struct ReferenceArgs {
  std::string scene_path, out;  // out not given: data/reference/<scene name>.json
  double rtol = 0;              // 0: the default
  bool quiet = false;
};

int reference(ReferenceArgs a) {
  using namespace vines::host;
  const Scene scene = load_scene(a.scene_path);
  std::string& out = a.out;
  if (out.empty()) out = "data/reference/" + safe_file_name(scene.name) + ".json";
  const reference::ReferenceReport rep = reference::reference_report(scene, a.rtol);
  // The file's folder made if missing, then the file written atomically.
  const std::filesystem::path dir = std::filesystem::path(out).parent_path();
  if (!dir.empty()) create_folder(dir.string());
  write_file_atomic(out, rep.to_json().dump(2) + '\n');
  if (!a.quiet) {
    const reference::Result& r = rep.run;
    std::printf("reference %s: rtol %.0e, %lld steps, %.2f s\n", scene.name.c_str(), rep.rtol, r.steps, r.wall_s);
    std::printf("  peak top displacement %.12f m at t = %.6f s; E_e %.10e J s; contacts %d\n", r.peak_top,
                r.t_peak_top, r.elastic_energy, r.contacts);
    std::printf("  x_r = %.4f %%   E_r = %.4f %%   (bare peak %.12f m)\n", 100 * rep.x_r(), 100 * rep.E_r(),
                rep.bare.peak_top);
    std::printf("  convergence vs rtol %.0e: peak %.1e, E_e %.1e (relative), contacts %s; written to %s\n",
                rep.rtol_coarse, reference::rel_diff(rep.coarse.peak_top, r.peak_top),
                reference::rel_diff(rep.coarse.elastic_energy, r.elastic_energy),
                rep.coarse.contacts == r.contacts ? "equal" : "DIFFER", out.c_str());
  }
  return kOk;
}

}  // namespace

void add_reference(CLI::App& vines) {
  auto a = std::make_shared<ReferenceArgs>();
  CLI::App* cmd = add_command(vines, "reference",
                              "Integrate the scene and its bare frame with the converged reference (DOP853 in long "
                              "double, events located to rounding) at rtol R and 100 R; writes FILE.",
                              "", [a] { return reference(*a); });
  cmd->add_option("SCENE.toml", a->scene_path,
                  "scene file (see data/scenes/README.md); its record at its sensor rate")
      ->required();
  cmd->add_option("--rtol", a->rtol,
                  "relative tolerance of the reference (default 1e-15, from 1e-17 to 1e-4); the convergence check "
                  "repeats every run at 100 R")
      ->type_name("R")
      ->check(number_in(1e-17, 1e-4));
  cmd->add_option("--out", a->out, "JSON output (default: data/reference/<scene name>.json)")
      ->type_name("FILE")
      ->check(non_empty_path());
  cmd->add_flag("--quiet", a->quiet, "print nothing but errors");
}

}  // namespace vines::cli
