// `vines design SCENE.toml --optimize NAME`: the best value of one design parameter.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <tuple>
#include <utility>

#include "sim_host/cli/cli.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/studies/design.hpp"

namespace vines::cli {
namespace {

struct DesignArgs {
  host::DesignOptions opt;
  std::string name, out_dir;  // out_dir not given: out/design_<scene name>
};

int design(DesignArgs a) {
  using namespace vines::host;
  DesignOptions& opt = a.opt;
  if (!design_parameter(a.name, &opt))
    throw CLI::ValidationError("--optimize", a.name + ": unknown (a scene key needs --range)");
  const Scene scene = load_scene(opt.scene_path);
  if (a.out_dir.empty()) a.out_dir = "out/design_" + safe_file_name(scene.name);
  const OutputDir out(a.out_dir, "vines design", {"design.json"});  // claimed before the search
  opt.stop = stop_on_interrupt("vines design", ", nothing will be written");
  DesignResult r;
  try {
    r = optimize_design(opt);
  } catch (const DesignInterrupted&) {
    std::fprintf(stderr, "vines design: interrupted; nothing written\n");
    return kInterrupted;
  }
  write_file_atomic(out.file("design.json"), r.to_json().dump(2) + '\n');
  out.finish({"design.json"});
  // The best value is of an ok run; degraded values were not candidates.
  if (!r.found) {
    std::fprintf(stderr, "vines design: DEGRADED: every one of the %zu values tried has a degraded run (reasons in "
                 "%s/design.json); no best value\n", r.evaluations.size(), a.out_dir.c_str());
    return kDegraded;
  }
  std::printf("design %s: best %s = %.6g, %s %s = %.2f %% (%zu evaluations; %s/design.json)\n", scene.name.c_str(),
              opt.key.c_str(), r.best_value, opt.objective.c_str(), opt.metric.c_str(), 100 * r.best_objective,
              r.evaluations.size(), a.out_dir.c_str());
  if (r.degraded() > 0)
    std::printf("  %zu values with a degraded run were not candidates (reasons in design.json)\n", r.degraded());
  return kOk;
}

}  // namespace

void add_design(CLI::App& vines) {
  auto a = std::make_shared<DesignArgs>();
  host::DesignOptions& opt = a->opt;
  CLI::App* cmd = add_command(vines, "design",
                              "Best value of one design parameter for the scene's record or a set of records (mean "
                              "or worst case): coarse grid, then golden-section refinement.",
                              "A value with a degraded run cannot be the best; when every value is degraded there is "
                              "no best (exit status 3). Ctrl-C stops the search after the runs under way; nothing is "
                              "written (exit status 130).",
                              [a] { return design(*a); });
  cmd->add_option("SCENE.toml", opt.scene_path, "scene file (see data/scenes/README.md)")->required();
  cmd->add_option("--optimize", a->name,
                  "beta (vines.beta, 1.05-2.0), eps (vines.eps, 0.1-1.0), mass_ratio (device.mass_ratio, "
                  "0.01-0.2), or any scene key TABLE.KEY with --range")
      ->type_name("NAME")
      ->required();
  cmd->add_option_function<std::pair<double, double>>(
         "--range",
         [&opt](const std::pair<double, double>& r) {
           if (!(std::isfinite(r.first) && std::isfinite(r.second) && r.first < r.second)) {
             char got[64];
             std::snprintf(got, sizeof got, "%g %g", r.first, r.second);
             throw CLI::ValidationError("--range", std::string("takes two numbers LO < HI, got ") + got);
           }
           std::tie(opt.lo, opt.hi) = r;
         },
         "search range (default per parameter)")
      ->type_name("LO HI");
  cmd->add_option("--records", opt.records,
                  "comma-separated record files (format detected; the scene's units); default: the scene's record")
      ->type_name("LIST")
      ->delimiter(',');
  cmd->add_option("--objective", opt.objective, "mean (default) or worst over the records")
      ->type_name("mean|worst")
      ->check(CLI::IsMember({"mean", "worst"}));
  cmd->add_option("--metric", opt.metric, "x_r (default) or E_r, maximised")
      ->type_name("x_r|E_r")
      ->check(CLI::IsMember({"x_r", "E_r"}));
  cmd->add_option("--coarse", opt.coarse, "coarse grid points (default 21, at least 3)")
      ->type_name("N")
      ->check(number_in(3, 1000));
  cmd->add_option("--refine", opt.refine, "golden-section steps (default 12)")->type_name("N")->check(number_in(1, 1000));
  cmd->add_option("--threads", opt.threads, "worker threads (default: all cores)")
      ->type_name("N")
      ->check(number_in(1, 1000));
  cmd->add_option("--out", a->out_dir,
                  "writes DIR/design.json; DIR new, empty or vines design's own (default: out/design_<scene name>)")
      ->type_name("DIR")
      ->check(non_empty_path());
}

}  // namespace vines::cli
