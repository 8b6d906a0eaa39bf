// `vines hil`: the bench against the real node process (`vines node`) on the
// El Centro VI NES scene. Clean runs equal the offline run bit for bit; each
// fault kind is injected, detected, survived; bad inputs give clear errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <sys/stat.h>

#include "sim_host/hil.hpp"

namespace vines::host {
namespace {

Scene vines_scene() { return load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines.toml"); }

HilOptions base(double duration_s) {
  HilOptions o;
  o.node_command = VINES_EXE;
  o.duration_s = duration_s;
  o.timeout_s = 20;
  return o;
}

long long faults_of(const nlohmann::json& j, const char* kind, const char* what) {
  return j["faults"].contains(kind) ? j["faults"][kind][what].get<long long>() : -1;
}

TEST(Hil, CleanRunEqualsTheOfflineRunBitForBit) {
  for (Scalar s : {Scalar::kDouble, Scalar::kFloat}) {
    Scene sc = vines_scene();
    sc.scalar = s;
    const nlohmann::json j = run_hil(sc, base(0));  // the whole record: 53761 samples
    EXPECT_EQ(j["samples"].get<long long>(), 53761);
    EXPECT_EQ(j["steps"].get<long long>(), 53761);
    EXPECT_TRUE(j["bit_exact"].get<bool>()) << scalar_name(s);
    EXPECT_EQ(j["max_deviation_from_offline"].get<double>(), 0.0);
    EXPECT_EQ(j["faults_injected"].get<long long>(), 0);
    EXPECT_TRUE(j["node_faults"].empty()) << j["node_faults"].dump();
    EXPECT_EQ(j["node_status"]["steps"].get<long long>(), 53761);
    EXPECT_GT(j["max_abs_floor_displacement_m"].get<double>(), 0.2);  // the run did something
  }
}

TEST(Hil, RealTimeRunKeepsPaceAndEqualsOffline) {
  HilOptions o = base(2.0);
  o.realtime = true;
  o.grace_periods = 1000;  // a loaded machine (CI) may send a sample late: no hold, so still exact
  const auto t0 = std::chrono::steady_clock::now();
  const nlohmann::json j = run_hil(vines_scene(), o);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(wall, 2.0);  // paced on the wall clock
  EXPECT_EQ(j["steps"].get<long long>(), 2001);
  EXPECT_TRUE(j["bit_exact"].get<bool>());
  EXPECT_GT(j["latency_us"]["mean"].get<double>(), 0.0);
}

// The node's deadline monitor reaches the report through STATUS: with a
// budget of 1 ns every step overruns, and the counts agree with the steps'
// own ticks in telemetry; with the default budget (one period, 1e6 ns on the
// host) the worst step is the one telemetry shows.
TEST(Hil, TheNodesDeadlineMonitorReachesTheReport) {
  HilOptions o = base(0.5);
  o.budget_ticks = 1;
  const nlohmann::json j = run_hil(vines_scene(), o);
  const auto& nd = j["node_deadline"];
  EXPECT_EQ(j["node"], "host");
  EXPECT_EQ(nd["counter_hz"].get<long long>(), 1000000000);
  EXPECT_EQ(nd["budget_ticks"].get<long long>(), 1);
  EXPECT_EQ(nd["overruns"].get<long long>(), 501);
  EXPECT_EQ(j["steps_over_budget"].get<long long>(), 501);
  const nlohmann::json d = run_hil(vines_scene(), base(0.5));
  EXPECT_EQ(d["node_deadline"]["budget_ticks"].get<long long>(), 1000000);
  EXPECT_EQ(d["node_deadline"]["worst_ticks"].get<double>(), d["step_ticks"]["max"].get<double>());
  EXPECT_EQ(d["node_deadline"]["overruns"].get<long long>(), d["steps_over_budget"].get<long long>());
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
    const nlohmann::json j = run_hil(vines_scene(), o);
    const char* name = fault_kind_name(c.kind);
    SCOPED_TRACE(name + std::string(": ") + j.dump());
    EXPECT_EQ(faults_of(j, name, "injected"), 3);
    EXPECT_EQ(faults_of(j, name, "detected"), 3);
    EXPECT_EQ(faults_of(j, name, "survived"), 3);
    EXPECT_EQ(j["faults_detected"].get<long long>(), 3);
    const auto& nf = j["node_faults"];
    if (c.kind == FaultKind::kCorrupt) EXPECT_GE(nf.value("crc", 0) + nf.value("framing", 0), 3);
    else if (c.node_code) EXPECT_GE(nf.value(c.node_code, 0), 3);
    EXPECT_TRUE(j["outputs_finite"].get<bool>());
    // A duplicate is dropped whole: the run is the clean one.
    EXPECT_EQ(j["bit_exact"].get<bool>(), c.kind == FaultKind::kDuplicate);
    if (c.kind != FaultKind::kDuplicate) EXPECT_GT(j["max_deviation_from_offline"].get<double>(), 0.0);
    EXPECT_LT(j["max_deviation_from_offline"].get<double>(), c.kind == FaultKind::kRestart ? 1.0 : 0.05);
    if (c.kind == FaultKind::kRestart) EXPECT_EQ(j["node_restarts"].get<long long>(), 3);
    else EXPECT_EQ(j["steps"].get<long long>(), 6001);
  }
}

TEST(Hil, DuplicatesChangeNothingAndDroppedSamplesAreInterpolated) {
  HilOptions o = base(6.0);
  o.faults[static_cast<int>(FaultKind::kDuplicate)] = parse_fault_spec("--duplicate", "0.05");
  nlohmann::json j = run_hil(vines_scene(), o);
  EXPECT_GT(j["faults_injected"].get<long long>(), 200);
  EXPECT_EQ(j["faults_detected"].get<long long>(), j["faults_injected"].get<long long>());
  EXPECT_EQ(j["max_deviation_from_offline"].get<double>(), 0.0);  // every duplicate dropped
  o = base(6.0);
  o.faults[static_cast<int>(FaultKind::kDrop)] = parse_fault_spec("--drop", "0.02");
  j = run_hil(vines_scene(), o);
  EXPECT_EQ(j["faults_detected"].get<long long>(), j["faults_injected"].get<long long>());
  EXPECT_GT(j["node_faults"]["seq_gap"].get<long long>(), 50);
  EXPECT_EQ(j["node_faults"].value("held", 0), 0);  // filled by interpolation, not held
  EXPECT_LT(j["max_deviation_from_offline"].get<double>(), 1e-3);
}

TEST(Hil, SaturatedSensorIsFlaggedOnEveryClippedSample) {
  HilOptions o = base(6.0);
  o.saturate_g = 0.2;  // El Centro peaks at 0.35 g
  const nlohmann::json j = run_hil(vines_scene(), o);
  const long long n = faults_of(j, "saturate", "injected");
  EXPECT_GT(n, 10);
  EXPECT_EQ(faults_of(j, "saturate", "detected"), n);
  EXPECT_TRUE(j["outputs_finite"].get<bool>());
}

TEST(Hil, MixedFaultsAtRatesKeepTheNodeBounded) {
  HilOptions o = base(10.0);
  for (int f = 0; f < kFaultKinds; ++f)
    if (static_cast<FaultKind>(f) != FaultKind::kSaturate && static_cast<FaultKind>(f) != FaultKind::kRestart)
      o.faults[f] = parse_fault_spec("--x", "0.005");
  o.seed = 7;
  const nlohmann::json j = run_hil(vines_scene(), o);
  EXPECT_GT(j["faults_injected"].get<long long>(), 20);
  EXPECT_EQ(j["faults_detected"].get<long long>(), j["faults_injected"].get<long long>()) << j["faults"].dump();
  EXPECT_EQ(j["faults_survived"].get<long long>(), j["faults_injected"].get<long long>());
  EXPECT_TRUE(j["outputs_finite"].get<bool>());
  EXPECT_EQ(j["bad_frames_from_node"].get<long long>(), 0);
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
