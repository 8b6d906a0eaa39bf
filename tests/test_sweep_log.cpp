// What makes a sweep durable: the plan's size from its axes, the log of
// finished runs (DIR/runs.jsonl) read back for --resume, and a map's stop.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/studies/parallel.hpp"
#include "sim_host/studies/sweep.hpp"
#include "sim_host/studies/sweep_log.hpp"

namespace {

using namespace vines::host;
namespace fs = std::filesystem;

// A grid axis of n numbers.
std::vector<KeyValue> axis(const std::string& key, int n) {
  std::vector<KeyValue> ax;
  for (int i = 0; i < n; ++i) ax.push_back(KeyValue{key, static_cast<double>(i), true, ""});
  return ax;
}

std::string values_text(const RunPlan& r) {
  std::string s = std::to_string(r.study);
  for (const KeyValue& v : r.values) s += " " + v.key + "=" + v.label();
  return s;
}

TEST(PlanSize, IsTheProductOfCasesAndAxesAndEveryRunCanBeBuiltAlone) {
  SweepSpec spec;
  StudySpec a, b;
  a.cases = {{KeyValue{"record.pga_g", 0.1, false, ""}}, {KeyValue{"record.pga_g", 0.2, false, ""}}};
  a.grid_axes = {axis("vines.beta", 3), axis("vines.eps", 4)};
  spec.studies = {a, b};  // b: one run, no grid
  ASSERT_EQ(plan_size(spec), 2u * 3 * 4 + 1);
  const std::vector<RunPlan> plan = plan_runs(spec);
  ASSERT_EQ(plan.size(), 25u);
  // Cases outer, last axis fastest; plan_run(i) is plan_runs()[i].
  EXPECT_EQ(values_text(plan[0]), "0 record.pga_g=0.1 vines.beta=0 vines.eps=0");
  EXPECT_EQ(values_text(plan[5]), "0 record.pga_g=0.1 vines.beta=1 vines.eps=1");
  EXPECT_EQ(values_text(plan[23]), "0 record.pga_g=0.2 vines.beta=2 vines.eps=3");
  EXPECT_EQ(values_text(plan[24]), "1");
  for (std::uint64_t i = 0; i < plan.size(); ++i) EXPECT_EQ(values_text(plan_run(spec, i)), values_text(plan[i]));
}

TEST(PlanSize, OverflowSaturatesInsteadOfWrapping) {
  SweepSpec spec;
  StudySpec st;
  for (const char* k : {"a.a", "a.b", "a.c", "a.d", "a.e"}) st.grid_axes.push_back(axis(k, 10000));  // 1e20 runs
  spec.studies = {st};
  EXPECT_EQ(plan_size(spec), std::numeric_limits<std::uint64_t>::max());
  spec.studies[0].grid_axes.resize(2);  // 1e8: exact
  EXPECT_EQ(plan_size(spec), 100000000u);
  spec.studies.push_back(spec.studies[0]);
  EXPECT_EQ(plan_size(spec), 200000000u);
}

// A log of the mini spec in a fresh folder.
struct Log : ::testing::Test {
  SweepSpec spec = load_sweep(std::string(VINES_TEST_DATA_DIR) + "/mini_sweep.toml");
  std::vector<RunPlan> plan = plan_runs(spec);
  std::string fingerprint = plan_fingerprint(spec, plan);
  fs::path dir = fs::temp_directory_path() / ("vines_log_" + std::to_string(::getpid()));
  std::string file = (dir / "runs.jsonl").string();
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }

  static RunResult result(double x) {
    RunResult r;
    r.done = true;
    r.device = "vines";
    r.x_r = x;
    r.E_r = 1.0 / 3.0;
    r.peak_top = std::numeric_limits<double>::infinity();
    r.residual = std::nan("");
    r.contacts = 42;
    return r;
  }
};

TEST_F(Log, RowsComeBackBitForBitWithNonFiniteNumbers) {
  SweepLog log(file, spec.path, fingerprint, plan.size(), 0);
  log.append(3, result(0.123456789012345678));
  RunResult failed;  // a failed run is finished too (run_one)
  failed.done = true;
  failed.error = "a \"quoted\"\nmessage";
  log.append(7, failed);
  log.close();
  const SweepLogContents c = read_sweep_log(file, fingerprint, plan.size());
  EXPECT_EQ(c.finished, 2u);
  EXPECT_TRUE(c.warning.empty()) << c.warning;
  EXPECT_EQ(c.good_bytes, fs::file_size(file));
  const RunResult& r = c.results[3];
  EXPECT_TRUE(r.done);
  EXPECT_EQ(r.x_r, 0.123456789012345678);
  EXPECT_EQ(r.E_r, 1.0 / 3.0);
  EXPECT_EQ(r.peak_top, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(r.residual));
  EXPECT_EQ(r.contacts, 42);
  EXPECT_EQ(r.device, "vines");
  EXPECT_EQ(c.results[7].error, failed.error);
  EXPECT_TRUE(c.results[7].done);
  EXPECT_FALSE(c.results[0].done);
}

TEST_F(Log, ATornLastLineIsLeftOutWithAWarningAndCutOnResume) {
  {
    SweepLog log(file, spec.path, fingerprint, plan.size(), 0);
    log.append(1, result(0.5));
    log.append(2, result(0.25));
    log.close();
  }
  const auto whole = fs::file_size(file);
  std::ofstream(file, std::ios::app) << R"({"run": 4, "result": {"x_r": 0.)";  // a power cut mid-line
  SweepLogContents c = read_sweep_log(file, fingerprint, plan.size());
  EXPECT_EQ(c.finished, 2u);
  EXPECT_FALSE(c.results[4].done);
  EXPECT_NE(c.warning.find("runs.jsonl:4: torn last line left out"), std::string::npos) << c.warning;
  EXPECT_EQ(c.good_bytes, whole);
  // Resuming cuts the torn line off and appends after the whole ones.
  SweepLog log(file, spec.path, fingerprint, plan.size(), c.good_bytes);
  log.append(4, result(0.75));
  log.close();
  c = read_sweep_log(file, fingerprint, plan.size());
  EXPECT_TRUE(c.warning.empty()) << c.warning;
  EXPECT_EQ(c.finished, 3u);
  EXPECT_EQ(c.results[4].x_r, 0.75);
}

TEST_F(Log, ALogOfAnotherPlanOrABadLineBeforeTheLastIsRefused) {
  {
    SweepLog log(file, spec.path, fingerprint, plan.size(), 0);
    log.append(0, result(0.5));
    log.close();
  }
  auto refusal = [&](const std::string& fp, std::size_t runs) {
    try {
      read_sweep_log(file, fp, runs);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("0000000000000000", plan.size()).find("of another spec or plan"), std::string::npos);
  EXPECT_NE(refusal(fingerprint, plan.size() + 1).find("of another spec or plan"), std::string::npos);
  // Another study key value changes the fingerprint.
  SweepSpec other = spec;
  other.studies[0].set[0].number = 100.0;
  EXPECT_NE(plan_fingerprint(other, plan), fingerprint);
  // A damaged line with whole lines after it is corruption, not a torn end.
  std::ofstream(file, std::ios::app) << "{not json\n" << R"({"run": 1, "result": {}})" << '\n';
  EXPECT_NE(refusal(fingerprint, plan.size()).find("runs.jsonl:3: bad line in the log"), std::string::npos);
  // So is a bad last line with its end of line: only a torn one is left out.
  {
    SweepLog log(file, spec.path, fingerprint, plan.size(), 0);
    log.append(0, result(0.5));
    log.close();
  }
  std::ofstream(file, std::ios::app) << "{not json\n";
  EXPECT_NE(refusal(fingerprint, plan.size()).find("runs.jsonl:3: bad line in the log"), std::string::npos);
  std::ofstream(file, std::ios::trunc) << "x,y\n1,2\n";
  EXPECT_NE(refusal(fingerprint, plan.size()).find("not a vines sweep log"), std::string::npos);
  EXPECT_THROW(read_sweep_log((dir / "none.jsonl").string(), fingerprint, plan.size()), std::runtime_error);
}

// Every line proves itself: its check, its run's index (in the plan, once),
// its result's members (each present, known, of its type) and that it
// finished. Lines an attacker or a broken writer made, each with a good
// check, are refused with their line number.
TEST_F(Log, EveryLineIsCheckedAndABadOneStopsTheResume) {
  const std::string good = R"({"result":{"E_r":0.5,"bad_samples":0,"cap_hits":0,"contacts":3,"degraded":false,)"
                           R"("degraded_reasons":"","device":"vines","divergences":0,"done":true,)"
                           R"("elastic_energy":1.0,"energy_checked":true,"error":"","max_overlap":0.0,)"
                           R"("peak_top":0.2,"residual":0.0,"x_r":0.25},"run":1})";
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const std::size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  auto verdict = [&](const std::vector<std::string>& lines) {
    {
      SweepLog log(file, spec.path, fingerprint, plan.size(), 0);
      log.close();
    }
    {
      std::ofstream f(file, std::ios::app);
      for (const std::string& l : lines) f << l;
    }
    try {
      return "accepted " + std::to_string(read_sweep_log(file, fingerprint, plan.size()).finished);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
  };
  const std::string at2 = file + ":2: bad line in the log: ";
  EXPECT_EQ(verdict({checked_log_line(good)}), "accepted 1");
  EXPECT_EQ(verdict({checked_log_line(with("\"x_r\":0.25", "\"x_r\":\"0.5\""))}), at2 + "\"x_r\" is not a number");
  EXPECT_EQ(verdict({checked_log_line(with(",\"contacts\":3", ""))}), at2 + "its result lacks \"contacts\"");
  EXPECT_EQ(verdict({checked_log_line(with("\"done\":true", "\"done\":false"))}),
            at2 + "its result is not finished (\"done\": false)");
  EXPECT_EQ(verdict({checked_log_line(with("\"run\":1", "\"run\":-1"))}), at2 + "its run is not an index");
  EXPECT_EQ(verdict({checked_log_line(with("\"run\":1", "\"run\":15"))}), at2 + "run 15 is not in the plan");
  EXPECT_EQ(verdict({checked_log_line(with("\"x_r\"", "\"x_rr\""))}),
            at2 + "its result has an unknown member \"x_rr\"");
  EXPECT_EQ(verdict({checked_log_line(with("\"contacts\":3", "\"contacts\":3.5"))}), at2 + "\"contacts\" is not a count");
  EXPECT_EQ(verdict({checked_log_line(good), checked_log_line(good)}),
            file + ":3: bad line in the log: run 1 is also on line 2");
  std::string flipped = checked_log_line(good);
  flipped[flipped.find("0.25") + 3] = '6';
  EXPECT_EQ(verdict({flipped}), at2 + "its check does not match its text (damaged)");
  EXPECT_EQ(verdict({good + "\n"}), at2 + "no check at its end");
}

// The fingerprint covers every record's bytes: a record changed between a
// sweep and its resume is another plan.
TEST_F(Log, ARecordChangedSinceTheSweepIsAnotherPlan) {
  const fs::path rec = dir / "record.txt", scene = dir / "scene.toml", spec_file = dir / "spec.toml";
  fs::copy_file(fs::path(VINES_SOURCE_DIR) / "../shared/data/ground_motions/elcentro_1940_ns_2688pts_dt002_time_g.dat",
                rec);
  std::ofstream(scene) << "[device]\nkind = \"none\"\n[record]\npath = \"record.txt\"\nformat = \"time-accel\"\n"
                          "units = \"g\"\n";
  std::ofstream(spec_file) << "[[study]]\nname = \"r\"\nscene = \"scene.toml\"\n[study.grid]\n"
                              "\"frame.stiffness_scale\" = [0.9, 1.0]\n";
  const SweepSpec s = load_sweep(spec_file.string());
  const std::vector<RunPlan> p = plan_runs(s);
  const std::string before = plan_fingerprint(s, p);
  EXPECT_EQ(plan_fingerprint(s, p), before);
  std::ofstream(rec, std::ios::app) << "60.0 0.01\n";
  EXPECT_NE(plan_fingerprint(s, p), before);
}

TEST_F(Log, AGridBeyondAnyMachineIsRefusedFromItsCounts) {
  const std::string spec_file = (dir / "huge.toml").string();
  std::ofstream(spec_file) << "[[study]]\nscene = \"" << VINES_SOURCE_DIR << "/data/scenes/elcentro_vines.toml\"\n"
                           << "[study.grid]\n\"vines.beta\" = { from = 1.1, to = 2.0, count = 100000 }\n"
                           << "\"vines.eps\" = [0.5, { from = 0.1, to = 1.0, count = 100000 }]\n";
  try {
    load_sweep(spec_file);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("huge.toml:1: the plan has 10000100000 runs, more than any sweep can hold"),
              std::string::npos)
        << e.what();
  }
}

TEST(ParallelMap, AJobThatSeesTheStopIsDroppedAndTheMapEndsQuietly) {
  std::atomic<bool> stop{false};
  std::atomic<int> finished{0};
  std::atomic<bool> ten_finished{false};
  parallel_map(1000, MapOptions{2, &stop, false}, [&](std::size_t i) {
    if (i == 10) stop = true;
    stop_point(&stop);
    ++finished;
    if (i == 10) ten_finished = true;
  });
  EXPECT_LT(finished.load(), 1000);
  EXPECT_FALSE(ten_finished.load());
  stop = false;
  EXPECT_NO_THROW(stop_point(&stop));
  EXPECT_NO_THROW(stop_point(nullptr));
}

}  // namespace
