// `vines stress`: random scenes, run and checked.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/stress.hpp"

namespace vines::cli {
namespace {

struct StressArgs {
  host::StressOptions opt;
  long long one_case = -1;  // >= 0: this case only, in full
  int worst = 5;
  bool as_json = false;
  std::string out_dir;
};

// Tables of a stress summary: checks, worst cases, refusals.
void print_stress(const nlohmann::json& s, int threads) {
  std::printf("stress: %zu cases (seed %llu), %zu refused at load, %zu failed; %.1f s, %.0f cases/s, %d thread%s\n",
              s["cases"].get<std::size_t>(), s["seed"].get<unsigned long long>(), s["refused"].get<std::size_t>(),
              s["failed"].get<std::size_t>(), s["wall_time_s"].get<double>(), s["cases_per_s"].get<double>(), threads,
              threads > 1 ? "s" : "");
  std::printf("\n%-12s %6s %7s %12s %12s\n", "check", "runs", "failed", "worst", "bound");
  for (const auto& [name, c] : s["checks"].items()) {
    const auto& w = c["worst"];
    std::printf("%-12s %6zu %7zu", name.c_str(), c["runs"].get<std::size_t>(), c["failed"].get<std::size_t>());
    if (w.empty()) std::printf(" %12s", "0");
    else std::printf(" %12.3g %12.3g", w[0]["value"].get<double>(), w[0]["bound"].get<double>());
    std::printf("\n");
  }
  std::printf("\nworst cases per check (re-run one with: vines stress --seed %llu --case K --json):\n",
              s["seed"].get<unsigned long long>());
  std::printf("%-12s %6s %10s %10s %3s %-11s %-6s %8s %7s %5s %5s %6s %-s\n", "check", "case", "value", "bound", "N",
              "device", "scalar", "rate_hz", "pga_x", "beta", "eps", "mu_%", "record");
  for (const auto& [name, c] : s["checks"].items())
    for (const auto& w : c["worst"]) {
      const auto& sc = w["scene"];
      const bool dev = sc["device"] != "none";
      std::printf("%-12s %6lld %10.3g %10.3g %3d %-11s %-6s %8.1f %7.3f %5s %5s %6s %s%s\n", name.c_str(),
                  sc["case"].get<long long>(), w["value"].get<double>(), w["bound"].get<double>(),
                  sc["stories"].get<int>(), sc["device"].get<std::string>().c_str(),
                  sc["scalar"].get<std::string>().c_str(), sc["sensor_rate_hz"].get<double>(),
                  sc["pga_scale"].get<double>(), dev ? std::to_string(sc["beta"].get<double>()).substr(0, 5).c_str() : "-",
                  dev ? std::to_string(sc["eps"].get<double>()).substr(0, 5).c_str() : "-",
                  dev ? std::to_string(100 * sc["mass_ratio"].get<double>()).substr(0, 6).c_str() : "-",
                  sc["record"].get<std::string>().c_str(), w["ok"].get<bool>() ? "" : "  FAIL");
    }
  if (!s["refusals"].empty()) {
    std::printf("\nrefused at scene load:\n");
    for (const auto& r : s["refusals"])
      std::printf("  %5zu x %s (e.g. case %lld)\n", r["cases"].get<std::size_t>(),
                  r["reason"].get<std::string>().c_str(), r["first_case"].get<long long>());
  }
}

int stress(const StressArgs& a) {
  using namespace vines::host;
  const StressOptions& opt = a.opt;
  const std::vector<StressRecord> records = load_stress_records();
  // One case, in full.
  if (a.one_case >= 0) {
    const StressCase c = draw_case(opt.seed, a.one_case, records, opt.limits);
    const StressResult r = run_case(c, records);
    nlohmann::json j = case_report(c, r, records);
    if (!a.out_dir.empty()) j["scene_file"] = write_case_scene(c, records, a.out_dir);
    std::printf("%s\n", j.dump(a.as_json ? -1 : 2).c_str());
    return r.ok() ? kOk : kRefused;
  }
  const std::atomic<bool>* stop = stop_on_interrupt();
  const StressRun run = run_stress(opt, records, stop);
  nlohmann::json s = stress_summary(opt, run, records, a.worst);
  if (!a.out_dir.empty()) {
    std::filesystem::create_directories(a.out_dir);
    for (auto& [name, c] : s["checks"].items())
      for (auto& w : c["worst"])
        w["scene_file"] = write_case_scene(run.cases[w["scene"]["case"].get<std::size_t>()], records, a.out_dir);
    std::ofstream(std::filesystem::path(a.out_dir) / "stress.json") << s.dump(2) << '\n';
    std::ofstream cases(std::filesystem::path(a.out_dir) / "cases.jsonl");
    for (std::size_t i = 0; i < run.results.size(); ++i)
      if (run.results[i].done) cases << case_report(run.cases[i], run.results[i], records).dump() << '\n';
  }
  const int threads = opt.threads > 0 ? opt.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (a.as_json) std::printf("%s\n", s.dump().c_str());
  else print_stress(s, threads);
  if (*stop) return kInterrupted;
  return s["passed"].get<bool>() ? kOk : kRefused;
}

}  // namespace

void add_stress(CLI::App& vines) {
  auto a = std::make_shared<StressArgs>();
  host::StressOptions& opt = a->opt;
  CLI::App* cmd = add_command(vines, "stress",
                              "Draw and run N random scenes (frames of 1-40 stories, every contact law, every "
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
                  "DIR/case_K.toml (with their record windows) that `vines run` runs as they were")
      ->type_name("DIR");
  cmd->add_flag_callback("--no-progress", [a] { a->opt.progress = false; }, "no progress on stderr");
}

}  // namespace vines::cli
