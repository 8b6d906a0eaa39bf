// The twin's commissioning baseline (docs/twin.md section 5): runs on the
// healthy building written to a baseline file, its statistics against a
// hand computation, a baseline of another building refused, a run its model
// does not explain not added, and a 5 % loss
// in a building that is not its drawing found against the baseline.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/modes/twin_baseline.hpp"
#include "sim_host/hil/modes/twin_design.hpp"

namespace vines::host {
namespace {

std::string scene_path(const std::string& name) { return std::string(VINES_SOURCE_DIR) + "/data/scenes/" + name; }
std::string data(const std::string& name) { return std::string(VINES_TEST_DATA_DIR) + "/" + name; }

HilOptions twin(const std::string& truth, unsigned seed) {
  HilOptions o;
  o.node_command = VINES_EXE;
  o.mode = HilMode::kTwin;
  o.duration_s = 30;
  o.timeout_s = 20;
  o.sensors = {3, 6, 8, 10};
  o.measure_noise_pct = 5;
  o.seed = seed;
  o.truth_path = data(truth);
  return o;
}

std::string temp_path(const char* name) {
  return "/tmp/vines_test_twin_baseline_" + std::to_string(::getpid()) + "_" + name;
}

// What f threw ("": nothing).
template <typename F>
std::string thrown(F f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

std::string refusal(const std::string& path, const TwinBuilding& b) {
  return thrown([&] { load_twin_baseline(path, b, TwinTuning{}); });
}

TEST(TwinDesign, ChiSquareQuantile) {
  // scipy.stats.chi2.isf(0.001, k) and isf(0.05, k)
  EXPECT_NEAR(chi_square_quantile(1, 0.001), 10.827566, 1e-5);
  EXPECT_NEAR(chi_square_quantile(2, 0.001), 13.815511, 1e-5);
  EXPECT_NEAR(chi_square_quantile(9, 0.001), 27.877165, 1e-5);
  EXPECT_NEAR(chi_square_quantile(10, 0.001), 29.588298, 1e-5);
  EXPECT_NEAR(chi_square_quantile(9, 0.05), 16.918978, 1e-5);
  EXPECT_EQ(chi_square_quantile(0, 0.001), 0.0);
  EXPECT_THROW(chi_square_quantile(9, 1.0), std::runtime_error);
  EXPECT_THROW(chi_square_quantile(9, 0.0), std::runtime_error);
}

TEST(TwinBaseline, StatisticsOfTheRuns) {
  const std::string path = temp_path("stats.json");
  std::ofstream(path) << R"({"format": "vines twin baseline", "version": 1, "stories": 2, "device": "none",
    "sensors": [2], "sensor_rate_hz": 1000.0, "runs": [
    {"truth": "a", "record": "r1", "loss": [0.01, -0.02], "loss_sd": [0.003, 0.004]},
    {"truth": "a", "record": "r2", "loss": [0.03, 0.00], "loss_sd": [0.001, 0.002]}]})";
  TwinTuning t;
  t.inflation = 4;
  const TwinBaselineStats s = load_twin_baseline(path, {2, "none", {2}, 1000.0}, t);
  EXPECT_EQ(s.runs, 2);
  EXPECT_NEAR(s.loss[0], 0.02, 1e-15);
  EXPECT_NEAR(s.loss[1], -0.01, 1e-15);
  // Spread (n - 1 in the denominator) times 1 + 1/n, plus c times the mean variance.
  EXPECT_NEAR(s.cov[0][0], 1.5 * 2e-4 + 4 * (9e-6 + 1e-6) / 2, 1e-15);
  EXPECT_NEAR(s.cov[1][1], 1.5 * 2e-4 + 4 * (16e-6 + 4e-6) / 2, 1e-15);
  EXPECT_NEAR(s.cov[0][1], 1.5 * 2e-4, 1e-15);
  EXPECT_EQ(s.cov[0][1], s.cov[1][0]);
  std::remove(path.c_str());
}

TEST(TwinBaseline, AnotherBuildingOrAFileThatIsNoBaselineRefused) {
  const std::string path = temp_path("refusals.json");
  const TwinBuilding b{10, "none", {3, 6, 8, 10}, 1000.0};
  EXPECT_NE(refusal(path, b).find("no such file"), std::string::npos);
  std::ofstream(path) << "[scene]\nname = \"x\"\n";
  EXPECT_NE(refusal(path, b).find("not a twin baseline"), std::string::npos);
  std::ofstream(path) << R"({"format": "vines twin baseline", "version": 7})";
  EXPECT_NE(refusal(path, b).find("baseline version 7, this program reads version 1"), std::string::npos);
  std::ofstream(path) << R"({"format": "vines twin baseline", "version": 1, "stories": 10, "device": "none",
    "sensors": [3, 6, 10], "sensor_rate_hz": 1000.0, "runs": []})";
  EXPECT_NE(refusal(path, b).find("a baseline of another building: its sensors is [3,6,10]"), std::string::npos)
      << refusal(path, b);
  std::ofstream(path) << R"({"format": "vines twin baseline", "version": 1, "stories": 10, "device": "none",
    "sensors": [3, 6, 8, 10], "sensor_rate_hz": 1000.0, "runs": []})";
  EXPECT_NE(refusal(path, b).find("no run"), std::string::npos);
  std::ofstream(path) << R"({"format": "vines twin baseline", "version": 1, "stories": 10, "device": "none",
    "sensors": [3, 6, 8, 10], "sensor_rate_hz": 1000.0, "runs": [{"loss": [0, 0], "loss_sd": [0, 0]}]})";
  EXPECT_NE(refusal(path, b).find("not a list of 10 numbers"), std::string::npos);
  // A file a commissioning run could not add to is refused before the run;
  // a missing one is fine (the run creates it).
  std::ofstream(path) << R"({"format": "vines twin baseline", "version": 1, "stories": 10, "device": "none",
    "sensors": [3, 6, 10], "sensor_rate_hz": 1000.0, "runs": []})";
  const std::string said = thrown([&] { check_commission_file(path, b); });
  EXPECT_NE(said.find("a baseline of another building"), std::string::npos) << said;
  std::remove(path.c_str());
  EXPECT_NO_THROW(check_commission_file(path, b));
}

// A run whose estimates a building of this drawing cannot have (its report's
// caveat) is not added: the file is not created, the refusal names it and
// the caveat.
TEST(TwinBaseline, RunTheModelDoesNotExplainNotCommissioned) {
  const std::string path = temp_path("caveat.json");
  std::remove(path.c_str());
  TwinBuilding b{2, "none", {1, 2}, 1000.0};
  HilTwinReport run;
  run.eta_k = {1.35, 0.97};
  run.eta_k_sd = {0.01, 0.01};
  run.caveat = "the estimates leave what a building of this drawing can be (story 1 at 1.350 of its drawing)";
  const std::string said = thrown([&] { commission_twin(path, b, run, "record.at2"); });
  EXPECT_NE(said.find(path), std::string::npos) << said;
  EXPECT_NE(said.find("not added"), std::string::npos) << said;
  EXPECT_NE(said.find("story 1 at 1.350"), std::string::npos) << said;
  struct stat st {};
  EXPECT_NE(::stat(path.c_str(), &st), 0) << "no file written";
  run.caveat.clear();
  commission_twin(path, b, run, "record.at2");
  EXPECT_EQ(::stat(path.c_str(), &st), 0);
  std::remove(path.c_str());
}

// Commissioned on two healthy runs (noise seeds) of a building whose stories
// are up to 2.5 % off the drawing, the twin finds a 5 % loss in story 6 from
// the start of the record against the baseline.
TEST(TwinBaseline, LossFoundAgainstTheCommissionedBuilding) {
  const std::string path = temp_path("commissioned.json");
  const Scene node = load_scene(scene_path("elcentro_bare.toml"));
  for (unsigned seed : {11u, 12u}) {
    const HilOptions o = twin("twin_bare_healthy_off.toml", seed);
    const HilReport r = run_hil(node, o);
    ASSERT_TRUE(r.twin);
    EXPECT_FALSE(r.twin->detected) << "the healthy building, seed " << seed;
    commission_twin(path, twin_building(node, o), *r.twin, node.record.path);
  }
  HilOptions o = twin("twin_bare_healthy_off_story6_loss5.toml", 13);
  o.baseline_path = path;
  const HilReport r = run_hil(node, o);
  ASSERT_TRUE(r.twin);
  const HilTwinReport& t = *r.twin;
  ASSERT_TRUE(t.detected);
  ASSERT_TRUE(t.story && t.size);
  EXPECT_EQ(*t.story, 6);
  EXPECT_NEAR(*t.size, 0.05, 0.015);
  std::printf("against the baseline: story %d, loss %.4f, at %.2f s\n", *t.story, *t.size, *t.detect_time_s);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace vines::host
