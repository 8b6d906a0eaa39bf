// Studies that share what their runs share: a built model given new initial
// conditions equals a fresh build bit for bit; a record folder as a grid key
// (glob, order, refusals) with statistics per record.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/engines/build_engine.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/studies/sweep.hpp"

namespace {

using namespace vines;
using namespace vines::host;
namespace fs = std::filesystem;

Scene scene_at_50hz(const std::string& name) {
  Scene s = load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/" + name);
  s.params.loop.sensor_rate_hz = 50.0;
  s.params.loop.floor_peaks = false;
  return s;
}

RunTotals run(Engine& e, const Excitation& ex) {
  e.init(ex.samples[0]);
  e.run(ex.samples.data() + 1, ex.samples.size() - 1);
  return e.totals();
}

void expect_same_bits(const RunTotals& a, const RunTotals& b) {
  EXPECT_EQ(0, std::memcmp(&a.peak_top, &b.peak_top, sizeof a.peak_top)) << a.peak_top << " " << b.peak_top;
  EXPECT_EQ(0, std::memcmp(&a.elastic_energy, &b.elastic_energy, sizeof(double)))
      << a.elastic_energy << " " << b.elastic_energy;
  EXPECT_EQ(0, std::memcmp(&a.max_overlap, &b.max_overlap, sizeof(double)));
  EXPECT_EQ(0, std::memcmp(&a.ledger, &b.ledger, sizeof a.ledger));
  EXPECT_EQ(0, std::memcmp(&a.count, &b.count, sizeof a.count));
}

// One engine built once and given each initial condition in turn runs as a
// fresh build of that initial condition: the same model image, the same
// totals, bit for bit (VI NES: walls and tolerances move with the start).
void check_reuse(const std::string& scene, const char* law_or_device,
                 const std::vector<std::pair<double, double>>& initial) {
  SCOPED_TRACE(std::string(scene) + " " + law_or_device);
  Scene s = scene_at_50hz(scene);
  const Excitation ex = load_excitation(s, "");
  const bool vines = s.params.device.kind == DeviceKind::kVines;
  std::unique_ptr<Engine> shared = build_engine(s.params, s.scalar, "shared");
  for (const auto& [x0, v0] : initial) {
    SceneParams p = s.params;
    if (vines) {
      p.device.vines.start_at_left_wall = false;
      p.device.vines.initial_position_m = x0 * shared->info().vines.gap;
      p.device.vines.initial_velocity_mps = v0;
    } else {
      p.device.tmd.initial_position_m = x0 * 0.1;
      p.device.tmd.initial_velocity_mps = v0;
    }
    ASSERT_TRUE(shared->set_initial_conditions(p).ok());
    std::unique_ptr<Engine> fresh = build_engine(p, s.scalar, "fresh");
    EXPECT_EQ(shared->model_image(), fresh->model_image()) << "x0 " << x0 << ", v0 " << v0;
    expect_same_bits(run(*shared, ex), run(*fresh, ex));
  }
}

TEST(SharedModel, NewInitialConditionsEqualAFreshBuild) {
  const std::vector<std::pair<double, double>> ic = {{0.37, -0.21}, {-1.0, 0.5}, {0.999, 0.0}, {-0.03, 0.77}};
  check_reuse("elcentro_vines.toml", "vines", ic);
  check_reuse("elcentro_tmd.toml", "tmd", ic);
}

TEST(SharedModel, AStartOutsideTheFreeTravelIsRefused) {
  Scene s = scene_at_50hz("elcentro_vines.toml");
  std::unique_ptr<Engine> e = build_engine(s.params, s.scalar, "shared");
  SceneParams p = s.params;
  p.device.vines.start_at_left_wall = false;
  p.device.vines.initial_position_m = 1.5 * e->info().vines.gap;
  const ParamError err = e->set_initial_conditions(p);
  EXPECT_EQ(std::string(err.field), "vines.initial_position_m");
}

// ---- record folders ----

struct Folder {
  fs::path dir;
  Folder() {
    dir = fs::temp_directory_path() / ("vines_record_folder_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                       "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Folder() { fs::remove_all(dir); }
  // A time-acceleration record [g]: a decaying sine of amplitude a, 12 s at 50 Hz.
  void record(const std::string& name, double a) const {
    std::ofstream f(dir / name);
    for (int i = 0; i <= 600; ++i) {
      const double t = 0.02 * i;
      f << t << ' ' << a * std::exp(-0.2 * t) * std::sin(2 * M_PI * 1.1 * t) << '\n';
    }
  }
  void text(const std::string& name, const std::string& body) const { std::ofstream(dir / name) << body; }
  // A spec over this folder (relative to the spec, which is written in it).
  std::string spec(const std::string& grid, const std::string& extra = "") const {
    const fs::path file = dir / "spec.toml";
    std::ofstream(file) << "[[study]]\nname = \"folder\"\nscene = \"" << VINES_SOURCE_DIR
                        << "/data/scenes/elcentro_vines.toml\"\n" << extra
                        << "[study.set]\n\"loop.sensor_rate_hz\" = 50.0\n\"output.rate_hz\" = 50.0\n"
                        << "[study.grid]\n" << grid;
    return file.string();
  }
};

std::string refusal(const std::string& spec) {
  try {
    load_sweep(spec);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(RecordFolder, GlobMatchesSortedFilesReadAsTheirOwnFormat) {
  Folder f;
  f.record("b_quake.dat", 0.3);
  f.record("a_quake.dat", 0.2);
  f.record("c_quake.dat", 0.25);
  f.text("notes.txt", "not a record\n");
  f.text(".hidden.dat", "0 0\n");
  const SweepSpec spec = load_sweep(f.spec("\"record.path\" = { folder = \".\", glob = \"*.dat\" }\n"));
  ASSERT_EQ(spec.studies.size(), 1u);
  ASSERT_EQ(spec.studies[0].grid_axes.size(), 1u);
  const std::vector<KeyValue>& ax = spec.studies[0].grid_axes[0];
  ASSERT_EQ(ax.size(), 3u);
  const char* names[] = {"a_quake.dat", "b_quake.dat", "c_quake.dat"};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(ax[i].text, (fs::absolute(f.dir) / names[i]).lexically_normal().string());
    EXPECT_TRUE(ax[i].record_file);
  }
}

TEST(RecordFolder, EmptyFoldersUnmatchedGlobsAndUnreadableFilesAreRefusedByName) {
  Folder f;
  fs::create_directories(f.dir / "empty");
  EXPECT_NE(refusal(f.spec("\"record.path\" = { folder = \"empty\", glob = \"*.at2\" }\n")).find("matches glob '*.at2'"),
            std::string::npos);
  EXPECT_NE(refusal(f.spec("\"record.path\" = { folder = \"empty\" }\n")).find((f.dir / "empty").string()),
            std::string::npos);
  EXPECT_NE(refusal(f.spec("\"record.path\" = { folder = \"missing\" }\n")).find("not a folder"), std::string::npos);
  f.record("good.dat", 0.2);
  f.text("bad.dat", "this is not\na record\n");
  const std::string bad = refusal(f.spec("\"record.path\" = { folder = \".\", glob = \"*.dat\" }\n"));
  EXPECT_NE(bad.find("bad.dat: cannot be read as a record file"), std::string::npos) << bad;
  EXPECT_NE(refusal(f.spec("\"vines.beta\" = { folder = \".\" }\n")).find("record.path only"), std::string::npos);
  EXPECT_NE(refusal(f.spec("\"record.path\" = { folder = \".\", glob = \"*.dat\", sort = 1 }\n")).find("sort"),
            std::string::npos);
}

// Statistics per record (a string group key) equal the mean, sample sd and
// range of each record's rows, computed here from the results.
TEST(RecordFolder, GroupByRecordGivesEachRecordsStatistics) {
  Folder f;
  f.record("one.dat", 0.15);
  f.record("two.dat", 0.35);
  const SweepSpec spec = load_sweep(
      f.spec("\"record.path\" = { folder = \".\", glob = \"*.dat\" }\n"
             "\"vines.initial_velocity_mps\" = { from = -1.0, to = 1.0, count = 4, scale = \"vmax\" }\n",
             "group_by = \"record.path\"\n"));
  const std::vector<RunPlan> plan = plan_runs(spec);
  ASSERT_EQ(plan.size(), 8u);
  const std::vector<RunResult> res = execute(spec, plan, 2, 0, 1, nullptr, false);
  const fs::path out = f.dir / "out";
  const SweepSummary s = write_sweep(spec, plan, res, out.string(), 1.0, 2);
  std::map<std::string, std::vector<double>> xr, er;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    ASSERT_TRUE(res[i].error.empty()) << res[i].error;
    ASSERT_FALSE(res[i].degraded) << res[i].degraded_reasons;
    xr[plan[i].values[0].text].push_back(res[i].x_r);
    er[plan[i].values[0].text].push_back(res[i].E_r);
  }
  const StudySummary& st = s.studies.at(0);
  ASSERT_EQ(st.groups.size(), 2u);
  for (const GroupSummary& g : st.groups) {
    SCOPED_TRACE(g.text);
    for (const auto& [want, got] : {std::pair{xr.at(g.text), g.x_r}, std::pair{er.at(g.text), g.E_r}}) {
      ASSERT_TRUE(got);
      ASSERT_EQ(want.size(), 4u);
      const double mean = (want[0] + want[1] + want[2] + want[3]) / 4;
      double ss = 0;
      for (double x : want) ss += (x - mean) * (x - mean);
      EXPECT_DOUBLE_EQ(got->mean, mean);
      EXPECT_NEAR(got->sd, std::sqrt(ss / 3), 1e-14);
      EXPECT_EQ(got->min, std::min(std::min(want[0], want[1]), std::min(want[2], want[3])));
      EXPECT_EQ(got->max, std::max(std::max(want[0], want[1]), std::max(want[2], want[3])));
      EXPECT_EQ(got->n, 4u);
    }
  }
  // The two records differ (0.15 g against 0.35 g): their statistics do too.
  EXPECT_NE(st.groups[0].x_r->mean, st.groups[1].x_r->mean);
  EXPECT_EQ(st.groups[0].text, (fs::absolute(f.dir) / "one.dat").lexically_normal().string());
  // summary.json names each group by its file, and the rate per core.
  std::ifstream js(out / "summary.json");
  const std::string text((std::istreambuf_iterator<char>(js)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("one.dat\""), std::string::npos);
  EXPECT_NE(text.find("\"runs_per_s_per_core\": 4.0"), std::string::npos) << text.substr(0, 400);
}

}  // namespace
