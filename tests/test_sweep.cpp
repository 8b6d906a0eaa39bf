// The paper's studies through `vines sweep` specs (data/studies/), checked
// against its published figures, and the sweep machinery itself.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/io/csv.hpp"
#include "sim_host/studies/design.hpp"
#include "sim_host/studies/parallel.hpp"
#include "sim_host/studies/sweep.hpp"

namespace {

using namespace vines::host;
namespace fs = std::filesystem;

std::string study_file(const std::string& name) {
  return std::string(VINES_SOURCE_DIR) + "/data/studies/" + name;
}

// Runs the named studies of a spec (all if none named) on 2 threads.
struct Sweep {
  SweepSpec spec;
  std::vector<RunPlan> plan;
  std::vector<RunResult> results;
  Sweep(const std::string& file, std::vector<std::string> only = {}, int threads = 2) {
    spec = load_sweep(study_file(file));
    if (!only.empty()) {
      std::vector<StudySpec> kept;
      for (const StudySpec& s : spec.studies)
        if (std::find(only.begin(), only.end(), s.name) != only.end()) kept.push_back(s);
      spec.studies = kept;
    }
    plan = plan_runs(spec);
    results = execute(spec, plan, threads, 0, 1, nullptr, false);
  }
  // (value of `key`, result) for the runs of study s.
  std::vector<std::pair<double, RunResult>> by(int s, const std::string& key) const {
    std::vector<std::pair<double, RunResult>> out;
    for (std::size_t i = 0; i < plan.size(); ++i) {
      if (plan[i].study != s) continue;
      EXPECT_TRUE(results[i].error.empty()) << results[i].error;
      double v = NAN;
      for (const KeyValue& kv : plan[i].values)
        if (kv.key == key) v = kv.number;
      out.emplace_back(v, results[i]);
    }
    return out;
  }
};

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}
double sd(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

TEST(Studies, ClearanceOptimumAndTmdReference) {
  const Sweep sw("clearance.toml");
  double best_beta = 0, best = -1;
  for (const auto& [beta, r] : sw.by(0, "vines.beta"))
    if (r.x_r > best) { best = r.x_r; best_beta = beta; }
  const double tmd = sw.by(1, "").front().second.x_r;
  EXPECT_GE(best_beta, 1.30);
  EXPECT_LE(best_beta, 1.40);
  EXPECT_GT(best, tmd);
  EXPECT_NEAR(tmd, 0.131, 0.01);
}

TEST(Studies, InitialConditionGridMatchesTable2) {
  const Sweep sw("initial_conditions.toml", {"ic_vines"});
  ASSERT_EQ(sw.plan.size(), 33u * 33u);
  std::vector<double> xr, er;
  for (const auto& [v, r] : sw.by(0, "")) {
    xr.push_back(r.x_r);
    er.push_back(r.E_r);
  }
  EXPECT_NEAR(mean(xr), 0.260, 0.02);
  EXPECT_NEAR(sd(xr), 0.043, 0.015);
  EXPECT_NEAR(mean(er), 0.605, 0.03);
}

// The IC grid states its contact tolerance (data/studies/tolerance.toml is
// the study behind it): at that tolerance the grid's statistics are those of
// a converged grid (1e-12) to the 0.01 points the study reports (checked at
// 0.02 points, x_r and E_r, mean and sd).
TEST(Studies, InitialConditionGridToleranceGivesConvergedStatistics) {
  Sweep stated("initial_conditions.toml", {"ic_vines"});
  double rtol = 0;
  for (const KeyValue& kv : stated.spec.studies[0].set)
    if (kv.key == "loop.contact_rtol") rtol = kv.number;
  ASSERT_GT(rtol, 1e-12) << "ic_vines states no loop.contact_rtol";
  SweepSpec tight = stated.spec;
  for (KeyValue& kv : tight.studies[0].set)
    if (kv.key == "loop.contact_rtol") kv.number = 1e-12;
  const std::vector<RunPlan> plan = plan_runs(tight);
  const std::vector<RunResult> converged = execute(tight, plan, 2, 0, 1, nullptr, false);
  std::vector<double> xr, er, xr_c, er_c;
  for (const auto& [v, r] : stated.by(0, "")) {
    xr.push_back(r.x_r);
    er.push_back(r.E_r);
  }
  for (const RunResult& r : converged) {
    ASSERT_TRUE(r.error.empty() && !r.degraded) << r.error << r.degraded_reasons;
    xr_c.push_back(r.x_r);
    er_c.push_back(r.E_r);
  }
  ASSERT_EQ(xr.size(), xr_c.size());
  EXPECT_NEAR(mean(xr), mean(xr_c), 2e-4) << "rtol " << rtol;
  EXPECT_NEAR(sd(xr), sd(xr_c), 2e-4) << "rtol " << rtol;
  EXPECT_NEAR(mean(er), mean(er_c), 2e-4) << "rtol " << rtol;
  EXPECT_NEAR(sd(er), sd(er_c), 2e-4) << "rtol " << rtol;
}

// The fixed-point engine over the IC grid (data/studies/fixed_point.toml):
// at 50 Hz and 1 kHz, the mean and sd of x_r and E_r in Q3.28 within 0.1
// points of double's with the same contact scheme (issue 34's target), no
// run saturated. Measured: at most 0.045 (means) and 0.089 (the 50 Hz sd
// of x_r; a sd over 1089 runs that part chaotically has a sampling error of
// ~0.09 points, docs/fixed_point.md).
TEST(Studies, FixedPointIcGridMatchesDouble) {
  const Sweep sw("fixed_point.toml");
  ASSERT_EQ(sw.spec.studies.size(), 4u);
  for (int s = 0; s < 4; s += 2) {
    std::vector<double> xr[2], er[2];
    for (int k = 0; k < 2; ++k)
      for (const auto& [v, r] : sw.by(s + k, "")) {
        EXPECT_FALSE(r.degraded) << sw.spec.studies[s + k].name << ": " << r.degraded_reasons;
        xr[k].push_back(r.x_r);
        er[k].push_back(r.E_r);
      }
    ASSERT_EQ(xr[0].size(), 33u * 33u);
    ASSERT_EQ(xr[1].size(), xr[0].size());
    const char* name = sw.spec.studies[s + 1].name.c_str();
    std::printf("%s: x_r %.4f %% +- %.4f (double %.4f +- %.4f), E_r %.4f %% +- %.4f (double %.4f +- %.4f)\n", name,
                100 * mean(xr[1]), 100 * sd(xr[1]), 100 * mean(xr[0]), 100 * sd(xr[0]), 100 * mean(er[1]),
                100 * sd(er[1]), 100 * mean(er[0]), 100 * sd(er[0]));
    EXPECT_NEAR(mean(xr[1]), mean(xr[0]), 1e-3) << name;
    EXPECT_NEAR(sd(xr[1]), sd(xr[0]), 1e-3) << name;
    EXPECT_NEAR(mean(er[1]), mean(er[0]), 1e-3) << name;
    EXPECT_NEAR(sd(er[1]), sd(er[0]), 1e-3) << name;
  }
}

// El Centro in fixed point against double over 20 draws a law (the sphere's
// initial speed in (0, 1e-4] m/s): each draw's peak within 1e-4, the means
// of x_r, E_r and the contact count as close as the issue asks. One draw's
// E_r is not: a pair's difference spreads by 0.8 to 1.5 points, as double's
// own does under such perturbations (docs/fixed_point.md).
TEST(Studies, FixedPointElCentroDrawsMatchDouble) {
  const Sweep sw("fixed_point_elcentro.toml");
  ASSERT_EQ(sw.spec.studies.size(), 6u);
  for (int s = 0; s < 6; s += 2) {
    const auto d = sw.by(s, "vines.initial_velocity_mps"), f = sw.by(s + 1, "vines.initial_velocity_mps");
    ASSERT_EQ(d.size(), 40u);
    ASSERT_EQ(f.size(), d.size());
    std::vector<double> xr[2], er[2], contacts[2];
    double worst_peak = 0;
    for (std::size_t i = 0; i < d.size(); ++i) {
      ASSERT_EQ(d[i].first, f[i].first);
      EXPECT_FALSE(f[i].second.degraded) << f[i].second.degraded_reasons;
      worst_peak = std::fmax(worst_peak, std::fabs(f[i].second.peak_top / d[i].second.peak_top - 1.0));
      for (int k = 0; k < 2; ++k) {
        const RunResult& r = (k ? f : d)[i].second;
        xr[k].push_back(r.x_r);
        er[k].push_back(r.E_r);
        contacts[k].push_back(static_cast<double>(r.contacts));
      }
    }
    const char* name = sw.spec.studies[s + 1].name.c_str();
    std::printf("%s: peaks within %.2e; x_r %.4f %% +- %.4f (double %.4f +- %.4f), E_r %.3f %% +- %.3f (double "
                "%.3f +- %.3f), contacts %.2f (%.2f)\n",
                name, worst_peak, 100 * mean(xr[1]), 100 * sd(xr[1]), 100 * mean(xr[0]), 100 * sd(xr[0]),
                100 * mean(er[1]), 100 * sd(er[1]), 100 * mean(er[0]), 100 * sd(er[0]), mean(contacts[1]),
                mean(contacts[0]));
    EXPECT_LT(worst_peak, 1e-4) << name;
    EXPECT_NEAR(mean(xr[1]), mean(xr[0]), 1e-3) << name;
    EXPECT_NEAR(mean(er[1]), mean(er[0]), 5e-3) << name;
    EXPECT_NEAR(mean(contacts[1]), mean(contacts[0]), 0.1 * mean(contacts[0])) << name;
  }
}

TEST(Studies, DamageHurtsTheTmdNotTheVines) {
  const Sweep sw("damage.toml");
  bool tmd_negative = false;
  for (const auto& [eta, r] : sw.by(1, "frame.stiffness_scale"))
    if (eta >= 0.85 - 1e-9 && eta <= 0.95 + 1e-9 && r.x_r < 0) tmd_negative = true;
  EXPECT_TRUE(tmd_negative);
  const auto vines = sw.by(0, "frame.stiffness_scale");
  EXPECT_EQ(vines.size(), 31u);
  for (const auto& [eta, r] : vines) EXPECT_GT(r.x_r, 0.0) << "eta_k " << eta;
}

TEST(Design, FindsTheClearanceOptimumByGridAndGoldenSection) {
  DesignOptions opt;
  opt.scene_path = std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines.toml";
  ASSERT_TRUE(design_parameter("beta", &opt));
  EXPECT_EQ(opt.key, "vines.beta");
  const DesignResult r = optimize_design(opt);
  const double beta = r.best_value, xr = r.best_objective;
  EXPECT_GE(beta, 1.30);
  EXPECT_LE(beta, 1.40);
  // Refinement never loses the grid's best.
  double grid_best = -1;
  for (const DesignEvaluation& e : r.evaluations)
    if (e.phase == "grid") grid_best = std::max(grid_best, e.objective);
  EXPECT_GE(xr, grid_best);
  EXPECT_GT(xr, 0.25);
}

TEST(Sweep, ResultsDoNotDependOnTheThreadCount) {
  const Sweep one("clearance.toml", {"clearance_vines"}, 1);
  const Sweep two("clearance.toml", {"clearance_vines"}, 2);
  ASSERT_EQ(one.results.size(), two.results.size());
  for (std::size_t i = 0; i < one.results.size(); ++i) {
    EXPECT_EQ(one.results[i].x_r, two.results[i].x_r) << i;
    EXPECT_EQ(one.results[i].E_r, two.results[i].E_r) << i;
    EXPECT_EQ(one.results[i].contacts, two.results[i].contacts) << i;
  }
}

TEST(Sweep, EveryRecordRunsForBothDevices) {
  const Sweep sw("records.toml");
  EXPECT_EQ(sw.plan.size(), 40u);
  for (const RunResult& r : sw.results) {
    EXPECT_TRUE(r.error.empty()) << r.error;
    EXPECT_LT(r.residual, 1e-6);
    EXPECT_EQ(r.cap_hits, 0);
  }
}

TEST(Sweep, BadSpecsAreRefusedWithTheirKey) {
  const fs::path dir = fs::temp_directory_path() / ("vines_sweep_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto refused = [&](const std::string& text, const std::string& needle) {
    const fs::path f = dir / "spec.toml";
    std::ofstream(f) << text;
    try {
      const SweepSpec s = load_sweep(f.string());
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  const std::string scene = "scene = \"" + std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines.toml\"\n";
  refused("[[study]]\nname = \"a\"\n", "needs scene");
  refused("[[study]]\n" + scene + "bogus = 1\n", "unknown key 'bogus'");
  refused("[[study]]\n" + scene + "[study.grid]\n\"vines.beta\" = { from = 1, to = 2 }\n", "needs 'step' or 'count'");
  refused("[[study]]\n" + scene + "[study.grid]\n\"vines.beta\" = { from = 1, to = 2, step = 0.1, scale = \"x\" }\n", "scale");
  refused("[[study]]\n" + scene + "optimize = \"speed\"\n", "optimize");
  refused("[[study]]\n" + scene + "group_by = \"vines.eps\"\n", "group_by");
  refused("[study\n", "TOML syntax error");
  refused("[[study]]\n" + scene + "[study.grid]\nbeta = [1.2]\n", "keys are table.key");
  refused("[[study]]\n" + scene + "[[study.cases]]\npath = \"x\"\n", "keys are table.key");
  // A typo in a key fails the spec at load, not every run.
  refused("[[study]]\n" + scene + "[study.grid]\n\"vines.betta\" = [1.2]\n",
          "vines.betta: not a scene key");
  // A key in two places, two studies of one name, values that would merge.
  refused("[[study]]\n" + scene + "[study.set]\n\"vines.beta\" = 1.3\n[study.grid]\n\"vines.beta\" = [1.2]\n",
          "vines.beta: set in both [study.set] and [study.grid]");
  refused("[[study]]\nname = \"a\"\n" + scene + "[[study]]\nname = \"a\"\n" + scene,
          "study 'a': a second study of that name");
  refused("[[study]]\n" + scene + "[study.grid]\n\"vines.beta\" = [1.2, 1.2000000000000002, 1.3]\n",
          "vines.beta: values 1.2 and 1.2000000000000002 differ by less than 1e-12 of their size");
  refused("[[study]]\n" + scene + "[study.grid]\n\"vines.beta\" = [1.2, 1.3, 1.2]\n",
          "vines.beta: 1.2 is listed twice (one run)");
  refused("[[study]]\n" + scene + "[study.grid]\n\"vines.law\" = [\"hertz\", \"tsuji\", \"hertz\"]\n",
          "vines.law: 'hertz' is listed twice (one run)");
  // Small values apart by more than 1e-12 of their size are two runs; ranges
  // that share an end, one run at it.
  for (const char* grid : {"\"loop.contact_rtol\" = [1e-14, 1e-13]\n",
                           "\"vines.beta\" = [{ from = 1.2, to = 1.3, step = 0.1 }, { from = 1.3, to = 1.4, step = 0.1 }]\n"}) {
    const fs::path g = dir / "small.toml";
    std::ofstream(g) << "[[study]]\n" << scene << "[study.grid]\n" << grid;
    const SweepSpec sp = load_sweep(g.string());
    EXPECT_EQ(plan_runs(sp).size(), std::string(grid).find("rtol") != std::string::npos ? 2u : 3u) << grid;
  }
  // A grid value the scene refuses fails that run with the scene's message.
  const fs::path f = dir / "bad_beta.toml";
  std::ofstream(f) << "[[study]]\n" << scene << "[study.grid]\n\"vines.beta\" = [0.9, 1.35]\n";
  SweepSpec spec = load_sweep(f.string());
  const auto plan = plan_runs(spec);
  const auto res = execute(spec, plan, 1, 0, 1, nullptr, false);
  EXPECT_NE(res[0].error.find("vines.beta"), std::string::npos) << res[0].error;
  EXPECT_TRUE(res[1].error.empty());
  fs::remove_all(dir);
}

// ---- the shared pieces: CSV writer, parallel map ----

TEST(Csv, QuotesWhatMustBeAndChecksWrites) {
  const fs::path f = fs::temp_directory_path() / ("vines_csv_" + std::to_string(::getpid()) + ".csv");
  CsvWriter csv(f.string());
  csv.raw("a").text("b,c").text("say \"hi\"").quoted("plain").number(0.1, "%.3g").integer(-7).empty();
  csv.end_row();
  csv.close();
  std::ifstream in(f);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "a,\"b,c\",\"say \"\"hi\"\"\",\"plain\",0.1,-7,");
  fs::remove(f);
  try {
    CsvWriter bad("/nonexistent-dir/x.csv");
    FAIL() << "opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.csv: cannot write"), std::string::npos) << e.what();
  }
}

TEST(ParallelMap, RunsEveryIndexOnceAndStopsWhenTold) {
  std::vector<std::atomic<int>> seen(1000);
  parallel_map(seen.size(), MapOptions{3, nullptr, false}, [&](std::size_t i) { ++seen[i]; });
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i].load(), 1) << i;
  // Stopped before it starts: nothing runs; an exception reaches the caller.
  std::atomic<bool> stop{true};
  std::atomic<int> ran{0};
  parallel_map(100, MapOptions{2, &stop, false}, [&](std::size_t) { ++ran; });
  EXPECT_EQ(ran.load(), 0);
  EXPECT_THROW(parallel_map(10, MapOptions{2, nullptr, false},
                            [](std::size_t i) { if (i == 5) throw std::runtime_error("job 5"); }),
               std::runtime_error);
}

}  // namespace
