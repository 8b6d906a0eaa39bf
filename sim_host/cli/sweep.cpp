// `vines sweep SPEC.toml`: the grid of runs of a study spec, on threads and MPI ranks.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/sweep.hpp"
#include "sim_host/sweep_mpi.hpp"

namespace vines::cli {
namespace {

struct SweepArgs {
  std::string spec_path;
  host::SweepOptions opt;
  bool accept_degraded = false;
};

int sweep(SweepArgs a) {
  using namespace vines::host;
  SweepOptions& opt = a.opt;
  Mpi mpi;
  const SweepSpec spec = load_sweep(a.spec_path);
  const std::vector<RunPlan> plan = plan_runs(spec);
  if (opt.out_dir.empty()) opt.out_dir = "out/" + std::filesystem::path(a.spec_path).stem().string();
  const std::atomic<bool>* stop = stop_on_interrupt();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<RunResult> results =
      execute(spec, plan, opt.threads, mpi.rank(), mpi.size(), stop, opt.progress && mpi.rank() == 0);
  mpi.gather(&results);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (mpi.rank() != 0) return kOk;
  const SweepSummary s = write_sweep(spec, plan, results, opt.out_dir, wall);
  std::printf("sweep %s: %zu of %zu runs in %.2f s (%.1f runs/s, %d rank%s), %zu failed, %zu degraded; results in "
              "%s/\n",
              a.spec_path.c_str(), s.done, plan.size(), wall, s.runs_per_s(), mpi.size(), mpi.size() > 1 ? "s" : "",
              s.failed, s.degraded, opt.out_dir.c_str());
  // A line per study that has results: x_r and E_r over its ok runs, the best value, the degraded runs.
  for (const StudySummary& st : s.studies) {
    if (st.runs == 0) continue;
    std::printf("  %-24s %-5s n=%-5zu", st.name.c_str(), st.device.c_str(), st.runs - st.degraded);
    if (st.x_r)
      std::printf(" x_r %6.2f %% +- %5.2f [%6.2f, %6.2f]  E_r %6.2f %% +- %5.2f", 100 * st.x_r->mean,
                  100 * st.x_r->sd, 100 * st.x_r->min, 100 * st.x_r->max, 100 * st.E_r->mean, 100 * st.E_r->sd);
    if (!st.optimize.empty() && !st.groups.empty()) std::printf("  best %s = %g", st.group_by.c_str(), st.best_value);
    if (st.degraded > 0) std::printf("  (%zu degraded, not counted)", st.degraded);
    if (!st.energy_checked) std::printf("  (energy balance not computed)");
    std::printf("\n");
  }
  if (*stop) {
    std::fprintf(stderr, "vines sweep: interrupted; kept the %zu finished runs\n", s.done);
    return kInterrupted;
  }
  if (s.failed > 0) return kRefused;
  if (s.degraded > 0)
    std::fprintf(stderr, "vines sweep: %zu runs DEGRADED (their status and reasons in %s/results.csv)\n", s.degraded,
                 opt.out_dir.c_str());
  return finished_status(s.degraded > 0, a.accept_degraded);
}

}  // namespace

void add_sweep(CLI::App& vines) {
  auto a = std::make_shared<SweepArgs>();
  CLI::App* cmd = add_command(vines, "sweep",
                              "Run the grid of scenes a study spec describes (data/studies/*.toml) on all cores (or "
                              "MPI ranks: mpirun -n K vines sweep ...); writes DIR/results.csv and "
                              "DIR/summary.json.",
                              "Ctrl-C stops after the runs under way and keeps what finished (exit status 130).",
                              [a] { return sweep(*a); });
  cmd->add_option("SPEC.toml", a->spec_path,
                  "study spec (format at the top of sim_host/sweep.hpp and in data/studies/README.md)")
      ->required();
  cmd->add_option("--out", a->opt.out_dir, "output folder (default: out/<spec name>)")->type_name("DIR");
  cmd->add_option("--threads", a->opt.threads, "worker threads (default: all cores; per rank under MPI)")
      ->type_name("N")
      ->check(number_in(1, 1024));
  cmd->add_flag_callback("--no-progress", [a] { a->opt.progress = false; }, "no progress bar / lines on stderr");
  add_accept_degraded(*cmd, &a->accept_degraded);
}

}  // namespace vines::cli
