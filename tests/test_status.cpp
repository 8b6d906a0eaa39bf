// The run status (sim_host/run/status.hpp): every result says ok or degraded and
// why; the bad inputs come out degraded with the right reason and exit
// status 3 (0 with --accept-degraded); the shipped scenes are ok.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "sim_host/run/run.hpp"
#include "sim_host/run/status.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/studies/design.hpp"
#include "sim_host/studies/sweep.hpp"

namespace {

using namespace vines::host;
namespace fs = std::filesystem;

const std::string kScenes = std::string(VINES_SOURCE_DIR) + "/data/scenes/";

// The shipped VI NES scene (El Centro, first 10 s, at the record's 50 Hz)
// with extra lines in its [vines] and [record] tables.
std::string vines_scene(const std::string& vines_extra, const std::string& record_extra = "") {
  return "[scene]\nname = \"status_case\"\n[frame]\npreset = \"table1\"\n[device]\nkind = \"vines\"\n"
         "mass_ratio = 0.05\n[vines]\nlaw = \"kuwabara\"\nbeta = 1.35\neps = 0.7\nv_ref_mps = 0.5\n" +
         vines_extra + "\n[record]\npath = \"elcentro_1940_ns_2688pts_dt002_time_g.dat\"\nformat = \"time-accel\"\n"
         "units = \"g\"\nduration_s = 10.0\n" + record_extra +
         "\n[loop]\nenergy_ledger = true\nsensor_rate_hz = 50.0\n[output]\nrate_hz = 50.0\n";
}

// The test's own folder, removed when the tests end.
fs::path test_dir() {
  struct Dir {
    fs::path path = fs::temp_directory_path() / ("vines_status_" + std::to_string(::getpid()));
    ~Dir() { fs::remove_all(path); }
  };
  static const Dir dir;
  fs::create_directories(dir.path);
  return dir.path;
}

// A scene text written to a file of the test's folder, its path.
std::string scene_file(const std::string& text) {
  const fs::path file = test_dir() / "case.toml";
  std::ofstream(file) << text;
  return file.string();
}

// The status of `vines run` on a scene text (nothing written).
RunStatus status_of(const std::string& text) {
  const Scene scene = parse_scene(text, kScenes + "status_case.toml");
  return run_scene(scene, RunOptions{}).status;
}

// The message of the reason `code`, or "" (no such reason).
std::string reason(const RunStatus& s, const std::string& code) {
  for (const StatusReason& r : s.reasons)
    if (r.code == code) return r.message;
  return "";
}
bool has(const RunStatus& s, const std::string& code) { return !reason(s, code).empty(); }

// `vines ARGS` exit status.
int vines(const std::string& args) {
  const int rc = std::system((std::string(VINES_EXE) + " " + args + " >/dev/null 2>&1").c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(Status, ShippedScenesAreOk) {
  for (const auto& e : fs::directory_iterator(kScenes)) {
    if (e.path().extension() != ".toml") continue;
    const RunReport r = run_scene(load_scene(e.path().string()), RunOptions{});
    EXPECT_TRUE(r.status.ok()) << e.path() << ": " << r.status.codes();
    const bool fixed = r.scalar == Scalar::kFixed;  // no ledger in fixed point yet
    EXPECT_EQ(r.status.energy_checked, !fixed) << e.path();
    EXPECT_EQ(r.to_json()["status"], "ok");
    EXPECT_TRUE(r.to_json()["degraded_reasons"].empty());
  }
}

// The inputs that load: a record at 1e6 g; a sphere soft enough to
// load but to sink past the overlap limit in a run. (A particle thrown at
// 1e6 m/s or a sphere of 1 Pa are refused at load: test_scene_limits.)
TEST(Status, RecordAtAMillionGIsDegradedByRollbacks) {
  const RunStatus s = status_of(vines_scene("", "scale = 1e6"));
  EXPECT_FALSE(s.ok());
  EXPECT_TRUE(has(s, "divergences_rolled_back")) << s.codes();
  EXPECT_TRUE(has(s, "bare_divergences_rolled_back")) << s.codes();
}

TEST(Status, SoftSphereOverlapsBeyondTheLimit) {
  const RunStatus s = status_of(vines_scene("young_pa = 1e9"));
  const std::string msg = reason(s, "overlap_beyond_limit");
  EXPECT_NE(msg.find("of the particle radius 1.19 m (limit 1 %"), std::string::npos) << s.codes() << ": " << msg;
}

// The bounds, on totals made up around them.
TEST(Status, ResidualAndOverlapBounds) {
  vines::SceneParams p;
  p.device.kind = vines::DeviceKind::kVines;
  p.loop.energy_ledger = true;
  ModelInfo info;
  info.vines.radius = 1.0;
  RunTotals t;
  t.ledger.max_input = 1.0;
  t.ledger.max_abs_residual = 0.5 * kResidualBoundDouble;
  t.max_overlap = 0.5 * kOverlapLimitOfRadius;
  EXPECT_TRUE(run_status(t, p, info, Scalar::kDouble).ok());
  t.ledger.max_abs_residual = 2 * kResidualBoundDouble;
  EXPECT_TRUE(has(run_status(t, p, info, Scalar::kDouble), "energy_residual"));
  EXPECT_TRUE(run_status(t, p, info, Scalar::kFloat).ok());  // float rounds more
  p.loop.energy_ledger = false;  // not computed: not checked, and said so
  EXPECT_TRUE(run_status(t, p, info, Scalar::kDouble).ok());
  EXPECT_FALSE(run_status(t, p, info, Scalar::kDouble).energy_checked);
  t.max_overlap = 2 * kOverlapLimitOfRadius;
  EXPECT_TRUE(has(run_status(t, p, info, Scalar::kDouble), "overlap_beyond_limit"));
}

// Each counter of the loop is a reason, with its figure and setting.
TEST(Status, CountersAreReasonsWithTheirFigures) {
  vines::SceneParams p;
  p.device.kind = vines::DeviceKind::kVines;
  ModelInfo info;
  info.vines.radius = 1.0;
  RunTotals t;
  t.count.bad_samples = 7;
  t.count.divergences = 3120;
  t.count.cap_hits = 5;
  p.loop.divergence_limit_m = 0.1;
  RunStatus s = run_status(t, p, info, Scalar::kDouble);
  ASSERT_EQ(s.codes(), "bad_samples_held;divergences_rolled_back;substep_cap_hits");
  EXPECT_EQ(s.reasons[1].message, "3120 steps rolled back (loop.divergence_limit_m = 0.1)");
  p.loop.contact_scheme = vines::ContactScheme::kBounded;
  EXPECT_TRUE(has(run_status(t, p, info, Scalar::kDouble), "events_deferred"));
  t = RunTotals{};
  t.peak_top = NAN;
  EXPECT_EQ(run_status(t, p, info, Scalar::kDouble).codes(), "non_finite_results");
  // The bare frame's reasons count too, marked as its own.
  RunTotals bare;
  bare.count.divergences = 1;
  bare.peak_top = bare.elastic_energy = 1.0;
  t = RunTotals{};
  s = device_status(t, &bare, p, info, Scalar::kDouble);
  ASSERT_EQ(s.codes(), "bare_divergences_rolled_back");
  EXPECT_EQ(s.reasons[0].message.rfind("bare frame: ", 0), 0u);
}

// A sweep over the divergence limit: the run at 0.1 m (the bare peak is
// 0.32 m) is degraded, counted apart and kept out of the statistics; the
// run at 100 m is ok.
TEST(Status, SweepCountsDegradedRunsApart) {
  const std::string spec_path = (test_dir() / "tight.toml").string();
  std::ofstream(spec_path) << "[[study]]\nname = \"tight\"\nscene = \"" << kScenes << "elcentro_vines.toml\"\n"
                           << "[study.set]\n\"loop.sensor_rate_hz\" = 50.0\n\"output.rate_hz\" = 50.0\n"
                           << "\"record.duration_s\" = 10.0\n"
                           << "[study.grid]\n\"loop.divergence_limit_m\" = [0.1, 100.0]\n";
  const SweepSpec spec = load_sweep(spec_path);
  const std::vector<RunPlan> plan = plan_runs(spec);
  const std::vector<RunResult> res = execute(spec, plan, 1, 0, 1, nullptr, false);
  ASSERT_EQ(res.size(), 2u);
  EXPECT_TRUE(res[0].degraded);
  EXPECT_GT(res[0].divergences, 0);
  EXPECT_NE(res[0].degraded_reasons.find("divergences_rolled_back"), std::string::npos);
  EXPECT_FALSE(res[1].degraded) << res[1].degraded_reasons;
  const fs::path out = test_dir() / "sweep_out";
  const SweepSummary s = write_sweep(spec, plan, res, out.string(), 0.0);
  EXPECT_EQ(s.degraded, 1u);
  EXPECT_EQ(s.studies[0].degraded, 1u);
  ASSERT_TRUE(s.studies[0].x_r);
  EXPECT_EQ(s.studies[0].x_r->n, 1u);
  EXPECT_EQ(s.studies[0].x_r->mean, res[1].x_r);
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  EXPECT_EQ(j["degraded"], 1);
  EXPECT_EQ(j["studies"][0]["degraded"], 1);
  std::ifstream csv(out / "results.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_NE(header.find("bad_samples_held,divergences_rolled_back,max_overlap_m,status,degraded_reasons,error"),
            std::string::npos) << header;
  EXPECT_NE(row.find(",degraded,divergences_rolled_back"), std::string::npos) << row;
}

// vines design: a value with a degraded run is never the best; with none ok
// there is no best (exit 3).
TEST(Status, DesignNeverPicksADegradedValue) {
  DesignOptions opt;
  opt.scene_path = scene_file(vines_scene(""));
  opt.key = "loop.divergence_limit_m";  // the bare peak is 0.32 m: 0.1 m clamps it
  opt.lo = 0.1;
  opt.hi = 100.0;
  opt.coarse = 3;
  opt.refine = 1;
  opt.threads = 1;
  DesignResult r = optimize_design(opt);
  ASSERT_TRUE(r.found);
  EXPECT_GT(r.best_value, 0.1);
  EXPECT_NE(r.evaluations[0].degraded_reasons.find("divergences_rolled_back"), std::string::npos);
  EXPECT_EQ(r.to_json()["evaluations"][0]["status"], "degraded");
  opt.hi = 0.2;
  r = optimize_design(opt);
  EXPECT_FALSE(r.found);
  EXPECT_EQ(r.degraded(), r.evaluations.size());
  EXPECT_TRUE(r.to_json()["best"].is_null());
  EXPECT_EQ(vines("design " + opt.scene_path + " --optimize loop.divergence_limit_m --range 0.1 0.2 --coarse 3 "
                  "--refine 1 --threads 1 --out " + (test_dir() / "design").string()),
            3);
}

// The command line: exit 3 on a degraded run, 0 with --accept-degraded (the
// status still written), 0 on an ok one.
TEST(Status, DegradedRunExitsThreeUnlessAccepted) {
  const std::string scene = scene_file(vines_scene("", "scale = 1e6"));
  const fs::path out = test_dir() / "run_out";
  EXPECT_EQ(vines("run " + scene + " --quiet --out " + out.string()), 3);
  EXPECT_EQ(vines("run " + scene + " --quiet --accept-degraded --out " + out.string()), 0);
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  EXPECT_EQ(j["status"], "degraded");
  EXPECT_EQ(j["degraded_reasons"][0]["code"], "divergences_rolled_back");
  EXPECT_EQ(vines("run " + kScenes + "elcentro_bare.toml --quiet --out " + out.string()), 0);
}

}  // namespace
