// `vines hil`: the bench against the real node process (`vines node`) on the
// El Centro VI NES scene. Clean runs equal the offline run bit for bit; each
// fault kind is injected, detected, survived; bad inputs give clear errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <sys/wait.h>

#include "sim_host/hil/hil.hpp"
#include "hil_support.hpp"

namespace vines::host {
namespace {

// The counts of one fault kind (all -1 if none was injected).
HilFaultCounts faults_of(const HilReport& r, const char* kind) {
  const auto it = r.faults.find(kind);
  return it != r.faults.end() ? it->second : HilFaultCounts{-1, -1, -1};
}

// The node's count of one fault code (0 if none).
long long node_faults(const HilReport& r, const char* code) {
  const auto it = r.node_faults.find(code);
  return it != r.node_faults.end() ? it->second : 0;
}

TEST(Hil, CleanRunEqualsTheOfflineRunBitForBit) {
  for (Scalar s : {Scalar::kDouble, Scalar::kFloat}) {
    Scene sc = vines_scene();
    sc.scalar = s;
    const HilReport r = run_hil(sc, base(0));  // the whole record: 53761 samples
    EXPECT_EQ(r.samples, 53761);
    EXPECT_EQ(r.steps, 53761);
    EXPECT_TRUE(r.bit_exact) << scalar_name(s);
    EXPECT_EQ(r.max_deviation_from_offline, 0.0);
    EXPECT_EQ(r.faults_injected, 0);
    EXPECT_TRUE(r.node_faults.empty()) << to_json(r)["node_faults"].dump();
    EXPECT_EQ(r.node_status.steps, 53761u);
    EXPECT_GT(r.max_abs_floor_displacement_m, 0.2);  // the run did something
    EXPECT_TRUE(r.survived);
  }
}

// The host node runs the fixed-point model image of each device (what the
// Cortex-M3 board loads), equal to the offline run; a scene asking for what
// fixed point does not keep is refused by key.
TEST(Hil, FixedPointNodeEqualsTheOfflineRun) {
  for (const char* device : {"bare", "tmd", "vines"}) {
    const Scene sc =
        load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_" + device + "_fixed.toml");
    const HilReport r = run_hil(sc, base(5));
    EXPECT_EQ(r.steps, 5001) << device;
    EXPECT_TRUE(r.bit_exact) << device;
    EXPECT_EQ(r.max_deviation_from_offline, 0.0) << device;
    EXPECT_GT(r.max_abs_floor_displacement_m, 0.01) << device;
  }
  // The energy ledger (the shipped scenes keep it): the bare frame's node
  // keeps it in fixed point too; a TMD's is refused by key.
  Scene ledger = load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_bare.toml");
  ASSERT_TRUE(ledger.params.loop.energy_ledger);
  ledger.scalar = Scalar::kFixed;
  const HilReport r = run_hil(ledger, base(1));
  EXPECT_TRUE(r.bit_exact);
  EXPECT_EQ(r.max_deviation_from_offline, 0.0);
  Scene tmd = load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_tmd.toml");
  tmd.scalar = Scalar::kFixed;
  try {
    run_hil(tmd, base(1));
    ADD_FAILURE() << "a fixed-point TMD node with the ledger ran";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("loop.energy_ledger"), std::string::npos) << e.what();
  }
}

TEST(Hil, RealTimeRunKeepsPaceAndEqualsOffline) {
  HilOptions o = base(2.0);
  o.realtime = true;
  o.grace_periods = 1000;  // a loaded machine (CI) may send a sample late: no hold, so still exact
  const auto t0 = std::chrono::steady_clock::now();
  const HilReport r = run_hil(vines_scene(), o);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(wall, 2.0);  // paced on the wall clock
  EXPECT_EQ(r.steps, 2001);
  EXPECT_TRUE(r.bit_exact);
  ASSERT_TRUE(r.latency_us);
  EXPECT_GT(r.latency_us->mean, 0.0);
}

// The node's deadline monitor reaches the report through STATUS: with a
// budget of 1 ns every step overruns, and the counts agree with the steps'
// own ticks in telemetry; with the default budget (one period, 1e6 ns on the
// host) the worst step is the one telemetry shows.
TEST(Hil, TheNodesDeadlineMonitorReachesTheReport) {
  HilOptions o = base(0.5);
  o.budget_ticks = 1;
  const HilReport r = run_hil(vines_scene(), o);
  const link::StepTiming& nd = r.node_deadline;
  EXPECT_EQ(r.node, "host");
  EXPECT_EQ(nd.counter_hz, 1000000000u);
  EXPECT_EQ(nd.budget_ticks, 1u);
  EXPECT_EQ(nd.overruns, 501u);
  EXPECT_EQ(r.steps_over_budget, 501);
  const HilReport d = run_hil(vines_scene(), base(0.5));
  EXPECT_EQ(d.node_deadline.budget_ticks, 1000000u);
  ASSERT_TRUE(d.step_ticks);
  EXPECT_EQ(static_cast<double>(d.node_deadline.worst_ticks), d.step_ticks->max);
  EXPECT_EQ(static_cast<long long>(d.node_deadline.overruns), d.steps_over_budget);
}

// Each kind at three samples: all detected and survived; the run stays
// finite and bounded, and differs from the clean run.
TEST(Hil, EveryFaultKindIsDetectedAndSurvived) {
  const struct {
    FaultKind kind;
    const char* node_code;
  } cases[] = {{FaultKind::kDrop, "seq_gap"},      {FaultKind::kCorrupt, nullptr},
               {FaultKind::kDuplicate, "duplicate"}, {FaultKind::kReorder, "reordered"},
               {FaultKind::kLate, "late"},          {FaultKind::kNonFinite, "non_finite"},
               {FaultKind::kStall, "stall"},        {FaultKind::kRestart, nullptr}};
  for (const auto& c : cases) {
    HilOptions o = base(6.0);
    o.faults[static_cast<int>(c.kind)] = parse_fault_spec("--x", "@1500,3000,4500");
    const HilReport r = run_hil(vines_scene(), o);
    const char* name = fault_kind_name(c.kind);
    SCOPED_TRACE(name + std::string(": ") + to_json(r).dump());
    EXPECT_EQ(faults_of(r, name).injected, 3);
    EXPECT_EQ(faults_of(r, name).detected, 3);
    EXPECT_EQ(faults_of(r, name).survived, 3);
    EXPECT_EQ(r.faults_detected, 3);
    if (c.kind == FaultKind::kCorrupt) EXPECT_GE(node_faults(r, "crc") + node_faults(r, "framing"), 3);
    else if (c.node_code) EXPECT_GE(node_faults(r, c.node_code), 3);
    EXPECT_TRUE(r.outputs_finite);
    // A duplicate is dropped whole: the run is the clean one.
    EXPECT_EQ(r.bit_exact, c.kind == FaultKind::kDuplicate);
    if (c.kind != FaultKind::kDuplicate) EXPECT_GT(r.max_deviation_from_offline, 0.0);
    EXPECT_LT(r.max_deviation_from_offline, c.kind == FaultKind::kRestart ? 1.0 : 0.05);
    if (c.kind == FaultKind::kRestart) EXPECT_EQ(r.node_restarts, 3);
    else EXPECT_EQ(r.steps, 6001);
    EXPECT_TRUE(r.survived);
    EXPECT_LE(faults_of(r, name).deviation_m, faults_of(r, name).bound_m);
    // A restarted node equals the clean run of its life (from rest at its
    // restart) bit for bit: what survival is judged against.
    if (c.kind == FaultKind::kRestart) EXPECT_EQ(faults_of(r, name).deviation_m, 0.0);
  }
}

// The CSV's latency column: each sample's telemetry arrival minus the
// sending of its frame in the same node life (0 without one).
std::vector<double> csv_latencies(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  std::vector<double> out;
  while (std::getline(f, line)) {
    std::size_t at = 0;
    for (int i = 0; i < 6; ++i) at = line.find(',', at) + 1;  // the 7th column: latency_us
    out.push_back(std::stod(line.substr(at)));
  }
  return out;
}

// Restarts at a rate: the steps are the samples stepped (never more), every
// latency counts from its frame's sending to the same node life, so none is
// negative and none carries the restart's own time; a restarted node's
// telemetry equals the clean run of its life.
TEST(Hil, RestartsAtARateKeepCountsAndLatenciesPerNodeLife) {
  HilOptions o = base(4.0);
  o.faults[static_cast<int>(FaultKind::kRestart)] = parse_fault_spec("--restart", "0.02");
  o.csv = testing::TempDir() + "hil_restarts.csv";
  const HilReport r = run_hil(vines_scene(), o);
  EXPECT_GT(r.node_restarts, 40);
  EXPECT_EQ(r.steps, r.samples);
  EXPECT_EQ(faults_of(r, "restart").deviation_m, 0.0);
  EXPECT_TRUE(r.survived);
  ASSERT_TRUE(r.latency_us);
  // A restart (a new process, configured) takes about 100 ms, a step tens of
  // us: with 2 % of the samples restarted, a p99 that counted the restarts
  // would be one.
  EXPECT_LT(r.latency_us->p99, 20e3) << to_json(r)["latency_us"].dump();
  for (double l : csv_latencies(o.csv)) EXPECT_GE(l, 0.0);
}

// In real time a restart (about 100 ms) puts the bench behind its schedule;
// the restarted node holds the samples whose deadlines passed before the
// bench sends them: those steps have no latency, and none is negative (it
// was, counted from when the bench handled the sample). Every sample but a
// few in flight at a kill has its step.
TEST(Hil, RealTimeRestartsLoseOnlyTheFramesInFlight) {
  HilOptions o = base(2.0);
  o.realtime = true;
  o.faults[static_cast<int>(FaultKind::kRestart)] = parse_fault_spec("--restart", "@500,800,1100");
  o.csv = testing::TempDir() + "hil_rt_restarts.csv";
  const HilReport r = run_hil(vines_scene(), o);
  EXPECT_EQ(r.node_restarts, 3);
  EXPECT_GE(r.steps, r.samples - 50) << to_json(r).dump();
  EXPECT_LE(r.steps, r.samples);
  for (double l : csv_latencies(o.csv)) EXPECT_GE(l, 0.0);
}

// A rate of 1 hits every sample after the first (not every other one), and
// listed samples side by side are all hit: the run says so and is not
// survived (no telemetry after the first sample).
TEST(Hil, RateOneHitsEverySampleAndListedNeighboursAreAllHit) {
  HilOptions o = base(1.0);
  o.faults[static_cast<int>(FaultKind::kDrop)] = parse_fault_spec("--drop", "1");
  HilReport r = run_hil(vines_scene(), o);
  EXPECT_EQ(faults_of(r, "drop").injected, 1000);
  EXPECT_EQ(faults_of(r, "drop").detected, 1000);
  EXPECT_EQ(r.steps, 1);
  EXPECT_EQ(r.missing_steps, 1000);
  EXPECT_FALSE(faults_of(r, "drop").ok);
  EXPECT_EQ(faults_of(r, "drop").survived, 0);
  EXPECT_GT(faults_of(r, "drop").unanswered, 0);
  EXPECT_FALSE(r.survived);
  o.faults[static_cast<int>(FaultKind::kDrop)] = parse_fault_spec("--drop", "@100,101,102");
  r = run_hil(vines_scene(), o);
  EXPECT_EQ(faults_of(r, "drop").injected, 3);
  EXPECT_EQ(faults_of(r, "drop").detected, 3);
  EXPECT_TRUE(r.survived);
}

// A 0.1 g sensor range on El Centro (0.35 g) multiplies the top floor's
// displacement about fivefold: not survived, with the deviation and the
// bound (the clean run's peak); `vines hil` exits 3 for it.
TEST(Hil, SaturationThatDistortsTheResponseIsNotSurvived) {
  HilOptions o = base(8.0);
  o.saturate_g = 0.1;
  const HilReport r = run_hil(vines_scene(), o);
  const HilFaultCounts c = faults_of(r, "saturate");
  EXPECT_GT(c.injected, 1000);
  EXPECT_EQ(c.detected, c.injected);
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.survived, 0);
  EXPECT_GT(c.deviation_m, 3 * c.bound_m);
  EXPECT_NEAR(c.bound_m, 0.231, 0.001);  // the clean run's peak top-floor displacement
  EXPECT_FALSE(r.survived);
  EXPECT_TRUE(r.outputs_finite);
  const std::string cmd = std::string(VINES_EXE) + " hil " + VINES_SOURCE_DIR +
                          "/data/scenes/elcentro_vines.toml --duration 8 --saturate 0.1 > /dev/null 2>&1";
  const int st = std::system(cmd.c_str());
  EXPECT_EQ(WIFEXITED(st) ? WEXITSTATUS(st) : -1, 3);
}

TEST(Hil, DuplicatesChangeNothingAndDroppedSamplesAreInterpolated) {
  HilOptions o = base(6.0);
  o.faults[static_cast<int>(FaultKind::kDuplicate)] = parse_fault_spec("--duplicate", "0.05");
  HilReport r = run_hil(vines_scene(), o);
  EXPECT_GT(r.faults_injected, 200);
  EXPECT_EQ(r.faults_detected, r.faults_injected);
  EXPECT_EQ(r.max_deviation_from_offline, 0.0);  // every duplicate dropped
  o = base(6.0);
  o.faults[static_cast<int>(FaultKind::kDrop)] = parse_fault_spec("--drop", "0.02");
  r = run_hil(vines_scene(), o);
  EXPECT_EQ(r.faults_detected, r.faults_injected);
  EXPECT_GT(node_faults(r, "seq_gap"), 50);
  EXPECT_EQ(node_faults(r, "held"), 0);  // filled by interpolation, not held
  EXPECT_LT(r.max_deviation_from_offline, 1e-3);
}

TEST(Hil, SaturatedSensorIsFlaggedOnEveryClippedSample) {
  HilOptions o = base(6.0);
  o.saturate_g = 0.2;  // El Centro peaks at 0.35 g
  const HilReport r = run_hil(vines_scene(), o);
  const long long n = faults_of(r, "saturate").injected;
  EXPECT_GT(n, 10);
  EXPECT_EQ(faults_of(r, "saturate").detected, n);
  EXPECT_TRUE(r.outputs_finite);
}

TEST(Hil, MixedFaultsAtRatesKeepTheNodeBounded) {
  HilOptions o = base(10.0);
  for (int f = 0; f < kFaultKinds; ++f)
    if (static_cast<FaultKind>(f) != FaultKind::kSaturate && static_cast<FaultKind>(f) != FaultKind::kRestart)
      o.faults[f] = parse_fault_spec("--x", "0.005");
  o.seed = 7;
  const HilReport r = run_hil(vines_scene(), o);
  EXPECT_GT(r.faults_injected, 20);
  EXPECT_EQ(r.faults_detected, r.faults_injected) << to_json(r)["faults"].dump();
  EXPECT_EQ(r.faults_survived, r.faults_injected);
  EXPECT_TRUE(r.survived);
  for (const auto& [name, c] : r.faults) EXPECT_LE(c.deviation_m, c.bound_m) << name;
  EXPECT_TRUE(r.outputs_finite);
  EXPECT_EQ(r.bad_frames_from_node, 0);
}

// The JSON report (`vines hil --json`, read by tools/mcu_report.py and
// hal/mcu/hil_check.py) keeps its keys.
TEST(Hil, JsonReportHasItsKeys) {
  const nlohmann::json j = to_json(run_hil(vines_scene(), base(0.2)));
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  const std::vector<std::string> expected = {
      "bad_frames_from_node", "bit_exact", "clock", "deadline_misses", "deadline_s", "faults", "faults_detected",
      "faults_injected", "faults_survived", "latency_us", "max_abs_floor_displacement_m",
      "max_deviation_from_offline", "missing_steps", "mode", "node", "node_deadline", "node_faults",
      "node_restarts", "node_status", "outputs_finite", "samples", "scalar", "scene", "sensor_rate_hz",
      "step_ticks", "steps", "steps_over_budget", "survival_bound_m", "survived", "wall_time_s"};
  EXPECT_EQ(keys, expected);
  EXPECT_EQ(j["mode"], "replay");
  EXPECT_EQ(j["clock"], "virtual");
  EXPECT_EQ(j["latency_us"].size(), 4u);
}

TEST(Hil, CsvHasOneRowPerSample) {
  HilOptions o = base(1.0);
  o.csv = testing::TempDir() + "hil.csv";
  run_hil(vines_scene(), o);
  std::ifstream f(o.csv);
  std::string line;
  int rows = 0;
  std::getline(f, line);
  EXPECT_EQ(line.rfind("k,t_s,", 0), 0u);
  while (std::getline(f, line)) ++rows;
  EXPECT_EQ(rows, 1001);
}

TEST(Hil, UserErrorsAreNamed) {
  EXPECT_THROW(parse_fault_spec("--drop", "2"), std::runtime_error);
  EXPECT_THROW(parse_fault_spec("--drop", "@3,x"), std::runtime_error);
  EXPECT_THROW(parse_fault_spec("--drop", "@0"), std::runtime_error);
  // A node that is not there, and one that never answers: errors, not hangs.
  HilOptions o = base(1.0);
  o.node_command = "/nonexistent/vines";
  EXPECT_THROW(run_hil(vines_scene(), o), std::runtime_error);
  const std::string script = testing::TempDir() + "silent_node.sh";
  std::ofstream(script) << "#!/bin/sh\nexec sleep 30\n";
  ::chmod(script.c_str(), 0755);
  o.node_command = script;
  o.timeout_s = 0.5;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    run_hil(vines_scene(), o);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no answer"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

}  // namespace
}  // namespace vines::host
