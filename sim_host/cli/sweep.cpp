// `vines sweep SPEC.toml`: the grid of runs of a study spec, on threads and MPI ranks.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/io/printable.hpp"
#include "sim_host/studies/parallel.hpp"
#include "sim_host/studies/sweep.hpp"
#include "sim_host/studies/sweep_log.hpp"
#include "sim_host/studies/sweep_mpi.hpp"

namespace vines::cli {
namespace {

struct SweepArgs {
  std::string spec_path, resume_dir;
  bool large = false;
  host::SweepOptions opt;
  const CLI::Option* out = nullptr;  // --out, given or not
  bool accept_degraded = false;
};

// A group value as printed: a file by its name.
std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

std::string duration_text(double s) {
  char t[32];
  if (s < 120) std::snprintf(t, sizeof t, "%.0f s", s);
  else if (s < 7200) std::snprintf(t, sizeof t, "%.0f min", s / 60);
  else std::snprintf(t, sizeof t, "%.1f h", s / 3600);
  return t;
}

// A plan above kLargePlan runs: its size, the memory its plan and results
// take, and (when that fits in memory) its time from a timed sample of runs;
// refused without --large, and whatever the options when it cannot fit.
// Returns false when Ctrl-C stopped the sample.
bool check_plan_size(const host::SweepSpec& spec, std::uint64_t n, const SweepArgs& a,
                     const std::atomic<bool>* stop) {
  using namespace vines::host;
  if (n <= kLargePlan) return true;
  const double memory = plan_memory_bytes(spec, n);
  const double ram = machine_memory_bytes();
  char size[160];
  std::snprintf(size, sizeof size, "%s: the plan has %llu runs (more than %llu) and needs about %.1f GB of memory",
                a.spec_path.c_str(), static_cast<unsigned long long>(n), static_cast<unsigned long long>(kLargePlan),
                memory / 1e9);
  if (memory > ram / 2)
    throw std::runtime_error(std::string(size) + ", more than half of this machine's " +
                             std::to_string(static_cast<long long>(ram / 1e9)) + " GB: split the grid");
  // Time: a few runs spread over the plan, on the threads the sweep will use.
  const int threads = map_threads(a.opt.threads);
  std::vector<RunPlan> sample;
  for (int k = 0; k < 2 * threads; ++k) sample.push_back(plan_run(spec, n / (2 * threads) * k));
  std::fprintf(stderr, "vines sweep: %s; timing %zu of its runs...\n", size, sample.size());
  const auto t0 = std::chrono::steady_clock::now();
  execute(spec, sample, a.opt.threads, 0, 1, stop, false);
  if (*stop) return false;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string time = "about " + duration_text(wall / sample.size() * static_cast<double>(n)) + " on " +
                           std::to_string(threads) + " threads";
  if (!a.large) throw std::runtime_error(std::string(size) + ", " + time + ": pass --large to run it");
  std::fprintf(stderr, "vines sweep: %llu runs, %s (--large)\n", static_cast<unsigned long long>(n), time.c_str());
  return true;
}

int sweep(SweepArgs a) {
  using namespace vines::host;
  SweepOptions& opt = a.opt;
  Mpi mpi;
  const SweepSpec spec = load_sweep(a.spec_path);
  const std::atomic<bool>* stop =
      stop_on_interrupt("vines sweep", ": runs under way are dropped, the finished ones kept");
  if (!check_plan_size(spec, plan_size(spec), a, stop)) return kInterrupted;
  const std::vector<RunPlan> plan = plan_runs(spec);
  if (!a.resume_dir.empty()) opt.out_dir = a.resume_dir;
  else if (a.out->count() == 0)
    opt.out_dir = "out/" + safe_file_name(std::filesystem::path(a.spec_path).stem().string());
  // The folder is claimed (and locked) before the runs by rank 0, which
  // writes it; its refusal stops every rank alike, none is left waiting.
  const std::string fingerprint = mpi.rank() == 0 ? plan_fingerprint(spec, plan) : std::string();
  std::optional<OutputDir> out;
  std::exception_ptr refused;
  if (mpi.rank() == 0) {
    try {
      out.emplace(opt.out_dir, "vines sweep", std::vector<std::string>{"results.csv", "summary.json", "runs.jsonl"},
                  fingerprint);
    } catch (const std::exception&) {
      refused = std::current_exception();
    }
  }
  if (!mpi.all(refused == nullptr)) {
    if (refused) std::rethrow_exception(refused);
    return kRefused;  // rank 0 says why
  }
  // The log of finished runs (one process only): read back with --resume, then appended to.
  std::unique_ptr<SweepLog> log;
  std::vector<RunResult> finished;
  std::size_t resumed = 0;  // runs read back from the log
  const std::string log_file = (std::filesystem::path(opt.out_dir) / "runs.jsonl").string();
  if (!a.resume_dir.empty() && mpi.size() > 1) throw std::runtime_error("--resume: not under MPI (no log is kept)");
  if (mpi.size() == 1) {
    std::size_t keep = 0;
    if (!a.resume_dir.empty()) {
      SweepLogContents c = read_sweep_log(log_file, fingerprint, plan.size());
      if (!c.warning.empty()) std::fprintf(stderr, "vines sweep: warning: %s\n", printable(c.warning).c_str());
      std::fprintf(stderr, "vines sweep: resuming %s: %zu of %zu runs finished, %zu to run\n", log_file.c_str(),
                   c.finished, plan.size(), plan.size() - c.finished);
      keep = c.good_bytes;
      resumed = c.finished;
      finished = std::move(c.results);
    }
    log = std::make_unique<SweepLog>(log_file, a.spec_path, fingerprint, plan.size(), keep);
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<RunResult> results = execute(spec, plan, opt.threads, mpi.rank(), mpi.size(), stop,
                                           opt.progress && mpi.rank() == 0, log.get(), std::move(finished));
  if (log) log->close();
  mpi.gather(&results);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (mpi.rank() != 0) return kOk;
  const int cores = map_threads(opt.threads) * mpi.size();
  const SweepSummary s = write_sweep(spec, plan, results, opt.out_dir, wall, cores);
  out->finish({"results.csv", "summary.json", "runs.jsonl"});
  // The rate of the runs run now (a resumed sweep read the others from its log).
  const std::size_t ran = s.done - resumed;
  const std::string from_log = resumed > 0 ? " (" + std::to_string(resumed) + " from the log)" : "";
  std::printf("sweep %s: %zu of %zu runs%s in %.2f s, %zu failed, %zu degraded; results in %s/\n",
              a.spec_path.c_str(), s.done, plan.size(), from_log.c_str(), wall, s.failed, s.degraded,
              opt.out_dir.c_str());
  // A line per study that has results: x_r and E_r over its ok runs, the best value, the degraded runs.
  for (const StudySummary& st : s.studies) {
    if (st.runs == 0) continue;
    std::printf("  %-24s %-5s n=%-5zu", st.name.c_str(), st.device.c_str(), st.runs - st.degraded);
    if (st.x_r)
      std::printf(" x_r %6.2f %% +- %5.2f [%6.2f, %6.2f]  E_r %6.2f %% +- %5.2f", 100 * st.x_r->mean,
                  100 * st.x_r->sd, 100 * st.x_r->min, 100 * st.x_r->max, 100 * st.E_r->mean, 100 * st.E_r->sd);
    if (!st.optimize.empty() && !st.groups.empty()) {
      if (st.best_text.empty()) std::printf("  best %s = %g", st.group_by.c_str(), st.best_value);
      else std::printf("  best %s = %s", st.group_by.c_str(), file_name(st.best_text).c_str());
    }
    if (st.degraded > 0) std::printf("  (%zu degraded, not counted)", st.degraded);
    if (!st.energy_checked) std::printf("  (energy balance not computed)");
    std::printf("\n");
    // Groups of a string key (a record folder): a line each.
    for (const GroupSummary& g : st.groups) {
      if (g.text.empty()) continue;
      std::printf("    %-56s n=%-5zu", file_name(g.text).c_str(), g.x_r ? g.x_r->n : std::size_t{0});
      if (g.x_r)
        std::printf(" x_r %6.2f %% +- %5.2f [%6.2f, %6.2f]  E_r %6.2f %% +- %5.2f", 100 * g.x_r->mean,
                    100 * g.x_r->sd, 100 * g.x_r->min, 100 * g.x_r->max, 100 * g.E_r->mean, 100 * g.E_r->sd);
      if (g.degraded > 0) std::printf("  (%zu degraded, not counted)", g.degraded);
      std::printf("\n");
    }
  }
  const double rate = wall > 0 ? static_cast<double>(ran) / wall : 0.0;
  std::printf("  %.1f runs/s, %.1f runs/s per core (%d core%s: %d rank%s x %d thread%s)\n", rate, rate / cores, cores,
              cores > 1 ? "s" : "", mpi.size(), mpi.size() > 1 ? "s" : "", cores / mpi.size(),
              cores / mpi.size() > 1 ? "s" : "");
  if (*stop) {
    std::fprintf(stderr,
                 "vines sweep: stopped (Ctrl-C): %s/results.csv and summary.json hold the %zu finished of %zu runs "
                 "(\"complete\": false); vines sweep %s --resume %s runs the rest\n",
                 opt.out_dir.c_str(), s.done, plan.size(), a.spec_path.c_str(), opt.out_dir.c_str());
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
                              "MPI ranks: mpirun -n K vines sweep ...); writes DIR/results.csv, "
                              "DIR/summary.json and DIR/runs.jsonl.",
                              "Every finished run is appended to DIR/runs.jsonl as it finishes (synced to disk every "
                              "0.2 s); results.csv and summary.json are written at the end, in plan order. Ctrl-C "
                              "drops the runs under way (within a second), writes the finished ones (\"complete\": "
                              "false) and exits 130; a second Ctrl-C exits 130 at once, the log intact. --resume DIR "
                              "runs only the runs its log lacks (no log under MPI). Plans of more than 1000000 runs "
                              "print their size, memory and time and need --large.",
                              [a] { return sweep(*a); });
  cmd->add_option("SPEC.toml", a->spec_path,
                  "study spec (format at the top of sim_host/studies/sweep.hpp and in data/studies/README.md)")
      ->required();
  a->out = cmd->add_option("--out", a->opt.out_dir,
                           "output folder: new, empty or vines sweep's own (default: out/<spec name>)")
               ->type_name("DIR")
               ->check(non_empty_path());
  cmd->add_option("--threads", a->opt.threads, "worker threads (default: all cores; per rank under MPI)")
      ->type_name("N")
      ->check(number_in(1, host::kMaxThreads));
  cmd->add_option("--resume", a->resume_dir,
                  "finish the sweep of this spec in DIR (its DIR/runs.jsonl): run only the runs not finished")
      ->type_name("DIR")
      ->excludes("--out");
  cmd->add_flag("--large", a->large, "run a plan of more than 1000000 runs");
  cmd->add_flag_callback("--no-progress", [a] { a->opt.progress = false; }, "no progress bar / lines on stderr (nor the size and time of a sweep over a minute)");
  add_accept_degraded(*cmd, &a->accept_degraded);
}

}  // namespace vines::cli
