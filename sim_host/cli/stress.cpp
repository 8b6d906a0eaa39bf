// `vines stress`: random scenes, run and checked.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/engines/engine.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/scene/names.hpp"
#include "sim_host/studies/parallel.hpp"
#include "sim_host/studies/stress.hpp"

namespace vines::cli {
namespace {

struct StressArgs {
  host::StressOptions opt;
  long long one_case = -1;  // >= 0: this case only, in full
  int worst = 5;
  bool as_json = false;
  std::string out_dir;
};

// The checks in the order the tables list them: by name.
std::vector<int> checks_by_name() {
  std::vector<int> order;
  for (int c = 0; c < host::kCheckCount; ++c) order.push_back(c);
  std::sort(order.begin(), order.end(),
            [](int x, int y) { return std::string(host::check_name(x)) < host::check_name(y); });
  return order;
}

// A VI NES number of a worst-case line, at most `width` characters ("-" without one).
std::string design_cell(bool vines, double v, std::size_t width) {
  return vines ? std::to_string(v).substr(0, width) : "-";
}

// Tables of a stress summary: checks, worst cases, refusals.
void print_stress(const host::StressSummary& s, const host::StressRun& run,
                  const std::vector<host::StressRecord>& records, int threads) {
  using namespace vines::host;
  std::printf("stress: %zu cases (seed %llu), %zu refused at load, %zu failed, %zu degraded; %.1f s, %.0f cases/s, "
              "%d thread%s\n",
              s.cases, static_cast<unsigned long long>(s.seed), s.refused, s.failed, s.degraded, s.wall_s,
              s.cases_per_s(), threads, threads > 1 ? "s" : "");
  // The frames drawn from: those of this build (tools/main.sh builds the 10-story frame only).
  const bool extra = compiled_frames(Scalar::kDouble, DeviceKind::kNone) != compiled_frames(Scalar::kDouble, DeviceKind::kTmd);
  std::printf("frames: %s%s\n", compiled_story_counts().c_str(),
              extra ? "" : "; no extra stress frames in this build: `cmake --preset release` and rebuild for the "
                           "release preset's 1, 3, 10, 20 and 40 stories");
  std::printf("\n%-12s %6s %7s %12s %12s\n", "check", "runs", "failed", "worst", "bound");
  for (int c : checks_by_name()) {
    const CheckSummary& k = s.checks[static_cast<std::size_t>(c)];
    std::printf("%-12s %6zu %7zu", check_name(c), k.runs, k.failed);
    if (k.worst.empty()) std::printf(" %12s", "0");
    else std::printf(" %12.3g %12.3g", k.worst[0].value, k.worst[0].bound);
    std::printf("\n");
  }
  std::printf("\nworst cases per check (re-run one with: vines stress --seed %llu --case K --json):\n",
              static_cast<unsigned long long>(s.seed));
  std::printf("%-12s %6s %10s %10s %3s %-11s %-6s %8s %7s %5s %5s %6s %-s\n", "check", "case", "value", "bound", "N",
              "device", "scalar", "rate_hz", "pga_x", "beta", "eps", "mu_%", "record");
  for (int c : checks_by_name())
    for (const WorstCase& w : s.checks[static_cast<std::size_t>(c)].worst) {
      const StressCase& sc = run.cases[w.index];
      const vines::DeviceParams& d = sc.params.device;
      const bool dev = d.kind == vines::DeviceKind::kVines;
      std::printf("%-12s %6lld %10.3g %10.3g %3d %-11s %-6s %8.1f %7.3f %5s %5s %6s %s%s\n", check_name(c),
                  static_cast<long long>(sc.index), w.value, w.bound, sc.params.frame.stories,
                  dev ? law_name(d.vines.law) : "none", scalar_name(sc.scalar), sc.params.loop.sensor_rate_hz,
                  sc.pga_scale, design_cell(dev, d.vines.beta, 5).c_str(), design_cell(dev, d.vines.eps, 5).c_str(),
                  design_cell(dev, 100 * d.mass_ratio, 6).c_str(),
                  records[static_cast<std::size_t>(sc.record)].file.c_str(), w.ok ? "" : "  FAIL");
    }
  if (!s.refusals.empty()) {
    std::printf("\nrefused at scene load:\n");
    for (const RefusalSummary& r : s.refusals)
      std::printf("  %5zu x %s (e.g. case %lld)\n", r.cases, r.reason.c_str(), static_cast<long long>(r.first_case));
  }
}

int stress(const StressArgs& a) {
  using namespace vines::host;
  const StressOptions& opt = a.opt;
  const std::vector<StressRecord> records = load_stress_records();
  // --out: the folder is claimed before the runs; the files written are noted
  // so that finish() removes those of an earlier run.
  std::optional<OutputDir> out;
  if (!a.out_dir.empty())
    out.emplace(a.out_dir, "vines stress",
                std::vector<std::string>{"stress.json", "cases.jsonl", "case_*.toml", "case_*_record.txt"});
  std::vector<std::string> written;
  auto write_scene = [&](const StressCase& c) {
    const std::string stem = "case_" + std::to_string(c.index);
    written.insert(written.end(), {stem + ".toml", stem + "_record.txt"});
    return write_case_scene(c, records, a.out_dir);
  };
  // One case, in full.
  if (a.one_case >= 0) {
    const StressCase c = draw_case(opt.seed, a.one_case, records, opt.limits);
    const StressResult r = run_case(c, records);
    nlohmann::json j = case_report(c, r, records);
    if (out) {
      j["scene_file"] = write_scene(c);
      out->finish(written);
    }
    std::printf("%s\n", j.dump(a.as_json ? -1 : 2).c_str());
    return r.ok() ? kOk : kRefused;
  }
  const std::atomic<bool>* stop = stop_on_interrupt("vines stress", ": the cases under way are dropped, the finished ones reported");
  const StressRun run = run_stress(opt, records, stop);
  StressSummary s = stress_summary(opt, run, a.worst);
  // --out: the worst cases as scenes, every case run, and stress.json last.
  if (out) {
    for (CheckSummary& c : s.checks)
      for (WorstCase& w : c.worst) w.scene_file = write_scene(run.cases[w.index]);
    std::string cases;
    for (std::size_t i = 0; i < run.results.size(); ++i)
      if (run.results[i].done) cases += case_report(run.cases[i], run.results[i], records).dump() + '\n';
    write_file_atomic(out->file("cases.jsonl"), cases);
    write_file_atomic(out->file("stress.json"), s.to_json(run, records).dump(2) + '\n');
    written.insert(written.end(), {"cases.jsonl", "stress.json"});
    out->finish(written);
  }
  if (a.as_json) std::printf("%s\n", s.to_json(run, records).dump().c_str());
  else print_stress(s, run, records, map_threads(opt.threads));
  if (*stop) return kInterrupted;
  return s.passed ? kOk : kRefused;
}

}  // namespace

void add_stress(CLI::App& vines) {
  auto a = std::make_shared<StressArgs>();
  host::StressOptions& opt = a->opt;
  CLI::App* cmd = add_command(vines, "stress",
                              "Draw and run N random scenes (frames of the story counts this build has, 1-40 in the "
                              "release preset; every contact law, every "
                              "record, PGA x0.05-20, 50 Hz-20 kHz) and check each: finite, energy balance, overlaps, "
                              "sub-step cap, loop guards, convergence at half the step.",
                              "Exit status 1 if any check fails, 130 if stopped by Ctrl-C.",
                              [a] { return stress(*a); });
  cmd->add_option("--count", opt.count, "random scenes to draw and run (default 2000)")
      ->type_name("N")
      ->check(number_in(1, 1e6));
  cmd->add_option("--seed", opt.seed, "seed of the draw (default 1); case K of seed S is always the same scene")
      ->type_name("S")
      ->check(number_in(0, static_cast<double>(std::numeric_limits<std::uint64_t>::max())));
  cmd->add_option("--threads", opt.threads, "worker threads (default: all cores); results do not depend on it")
      ->type_name("N")
      ->check(number_in(1, 1024));
  cmd->add_option("--case", a->one_case, "draw and run only case K, and report it in full")
      ->type_name("K")
      ->check(number_in(0, static_cast<double>(1ll << 62)));
  cmd->add_option("--worst", a->worst, "cases listed per check (default 5)")->type_name("W")->check(number_in(1, 1024));
  cmd->add_flag("--json", a->as_json, "print one JSON object instead of tables");
  cmd->add_option("--out", a->out_dir,
                  "write DIR/stress.json, every case to DIR/cases.jsonl, and the listed cases as scenes "
                  "DIR/case_K.toml (with their record windows) that `vines run` runs as they were; DIR new, empty "
                  "or vines stress's own (its files of an earlier run that this run does not write are removed)")
      ->type_name("DIR")
      ->check(non_empty_path());
  cmd->add_flag_callback("--no-progress", [a] { a->opt.progress = false; }, "no progress on stderr");
}

}  // namespace vines::cli
