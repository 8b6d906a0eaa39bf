// Scene files: the shipped scenes parse to the docs/model.md defaults, the
// accepted variants, and record files are found where resolve_record_path
// says. Refused scenes: test_scene_errors.cpp.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/scene/table.hpp"

#include "scene_support.hpp"

namespace {

using namespace vines::scene_test;

// ---- shipped scenes ----

// What every shipped scene shares: Table 1 frame, El Centro, 1000 / 100 Hz.
void expect_common(const Scene& s) {
  const vines::FrameParams& f = s.params.frame;
  EXPECT_EQ(f.stories, 10);
  EXPECT_DOUBLE_EQ(f.mass_kg[0], 179000.0);
  EXPECT_DOUBLE_EQ(f.mass_kg[9], 98000.0);
  EXPECT_DOUBLE_EQ(f.stiffness_n_per_m[0], 62.47e6);
  EXPECT_DOUBLE_EQ(f.stiffness_n_per_m[1], 52.26e6);
  EXPECT_DOUBLE_EQ(f.stiffness_n_per_m[9], 34.31e6);
  EXPECT_EQ(f.damping, DampingRule::kStiffnessProportional);
  EXPECT_DOUBLE_EQ(f.stiffness_damping_s, 0.0129);
  EXPECT_DOUBLE_EQ(f.stiffness_scale, 1.0);
  EXPECT_EQ(s.record.path, kElCentro);
  EXPECT_EQ(s.record.format, vines::hal::RecordFormat::kTimeAccel);
  EXPECT_EQ(s.record.units, vines::hal::Units::kG);
  EXPECT_DOUBLE_EQ(s.record.scale, 1.0);
  EXPECT_EQ(s.duration_s, 0.0);
  EXPECT_EQ(s.target_pga_mps2, 0.0);
  EXPECT_DOUBLE_EQ(s.params.loop.sensor_rate_hz, 1000.0);
  EXPECT_DOUBLE_EQ(s.output.rate_hz, 100.0);
  EXPECT_TRUE(s.output.timeseries);
  EXPECT_EQ(s.scalar, vines::host::Scalar::kDouble);
  EXPECT_EQ(s.params.device.floor, 0);  // top
  EXPECT_DOUBLE_EQ(s.params.device.mass_ratio, 0.05);
  EXPECT_EQ(s.params.device.mass_kg, 0.0);
  // The record is found through the default ground-motion folder.
  EXPECT_TRUE(fs::is_regular_file(resolve_record_path(s.record.path, s.path)));
}

TEST(Scene, Bare) {
  const Scene s = load_scene(kScenes + "elcentro_bare.toml");
  expect_common(s);
  EXPECT_EQ(s.name, "elcentro_bare");
  EXPECT_EQ(s.params.device.kind, DeviceKind::kNone);
}

TEST(Scene, Tmd) {
  const Scene s = load_scene(kScenes + "elcentro_tmd.toml");
  expect_common(s);
  EXPECT_EQ(s.params.device.kind, DeviceKind::kTmd);
  EXPECT_EQ(s.params.device.tmd.k_n_per_m, 0.0);  // Den Hartog
  EXPECT_EQ(s.params.device.tmd.c_ns_per_m, 0.0);
}

TEST(Scene, VinesLaws) {
  const std::pair<const char*, ContactLaw> files[] = {
      {"elcentro_vines", ContactLaw::kKuwabara},
      {"elcentro_vines_tsuji", ContactLaw::kTsuji},
      {"elcentro_vines_hertz", ContactLaw::kHertz},
      {"elcentro_vines_restitution", ContactLaw::kRestitution}};
  for (const auto& [stem, law] : files) {
    SCOPED_TRACE(stem);
    const Scene s = load_scene(kScenes + stem + ".toml");
    expect_common(s);
    EXPECT_EQ(s.name, stem);
    const vines::VinesParams& v = s.params.device.vines;
    EXPECT_EQ(s.params.device.kind, DeviceKind::kVines);
    EXPECT_EQ(v.law, law);
    EXPECT_DOUBLE_EQ(v.beta, 1.35);
    EXPECT_EQ(v.box_length_m, 0.0);
    EXPECT_EQ(v.radius_m, 0.0);
    EXPECT_DOUBLE_EQ(v.density_kg_m3, 8000.0);
    EXPECT_DOUBLE_EQ(v.young_pa, 210e9);
    EXPECT_DOUBLE_EQ(v.poisson, 0.3);
    EXPECT_DOUBLE_EQ(v.eps, 0.7);
    EXPECT_DOUBLE_EQ(v.v_ref_mps, 0.5);
    EXPECT_EQ(v.tau_s, 0.0);
    EXPECT_TRUE(v.start_at_left_wall);
    EXPECT_EQ(v.initial_velocity_mps, 0.0);
  }
}

// ---- accepted variants ----

TEST(Scene, MinimalDefaults) {
  const Scene s = parse_scene(kBase, "dir/minimal.toml");
  EXPECT_EQ(s.name, "minimal");
  EXPECT_EQ(s.path, "dir/minimal.toml");
  EXPECT_EQ(s.record.format, vines::hal::RecordFormat::kAuto);
  EXPECT_EQ(s.params.device.vines.law, ContactLaw::kKuwabara);
  // No [device] at all: no device.
  EXPECT_EQ(parse_scene("[record]\npath = \"x.dat\"\n", "x").params.device.kind, DeviceKind::kNone);
}

TEST(Scene, CustomFrameRayleighAndHostKeys) {
  const Scene s = parse_scene(R"(
[scene]
name = "custom"
[frame]
preset = "custom"
masses_kg = [1000, 2000.5, 3000]
stiffnesses_n_per_m = [1e6, 2e6, 3e6]
damping = "rayleigh"
rayleigh_zeta = [0.01, 0.03]
rayleigh_modes = [1, 3]
stiffness_scale = 0.8
[device]
kind = "tmd"
floor = 2
mass_kg = 150
[tmd]
k_n_per_m = 2500
c_ns_per_m = 30
initial_position_m = 0.01
[vines]                # inactive: read, ignored
beta = 0.5
[record]
path = "/abs/rec.txt"
format = "accel"
units = "cm/s2"
dt_s = 0.01
pga_g = 0.4
duration_s = 20
[loop]
sensor_rate_hz = 2000
scalar = "float"
energy_ledger = false
max_substeps_per_step = 100
[output]
rate_hz = 250
timeseries = false
)",
                              "x");
  const vines::FrameParams& f = s.params.frame;
  EXPECT_EQ(s.name, "custom");
  EXPECT_EQ(f.stories, 3);
  EXPECT_DOUBLE_EQ(f.mass_kg[1], 2000.5);
  EXPECT_DOUBLE_EQ(f.stiffness_n_per_m[2], 3e6);
  EXPECT_EQ(f.damping, DampingRule::kRayleigh);
  EXPECT_DOUBLE_EQ(f.rayleigh_zeta[1], 0.03);
  EXPECT_EQ(f.rayleigh_modes[1], 3);
  EXPECT_DOUBLE_EQ(f.stiffness_scale, 0.8);
  EXPECT_EQ(s.params.device.kind, DeviceKind::kTmd);
  EXPECT_EQ(s.params.device.floor, 2);
  EXPECT_DOUBLE_EQ(s.params.device.mass_kg, 150.0);
  EXPECT_DOUBLE_EQ(s.params.device.tmd.k_n_per_m, 2500.0);
  EXPECT_DOUBLE_EQ(s.params.device.tmd.c_ns_per_m, 30.0);
  EXPECT_DOUBLE_EQ(s.params.device.tmd.initial_position_m, 0.01);
  EXPECT_DOUBLE_EQ(s.params.device.vines.beta, 0.5);  // inactive, not range-checked
  EXPECT_EQ(s.record.format, vines::hal::RecordFormat::kAccel);
  EXPECT_EQ(s.record.units, vines::hal::Units::kCmps2);
  EXPECT_DOUBLE_EQ(s.record.dt_s, 0.01);
  EXPECT_DOUBLE_EQ(s.target_pga_mps2, 0.4 * vines::kGravity);
  EXPECT_DOUBLE_EQ(s.duration_s, 20.0);
  EXPECT_DOUBLE_EQ(s.params.loop.sensor_rate_hz, 2000.0);
  EXPECT_EQ(s.params.loop.max_substeps_per_step, 100);
  EXPECT_FALSE(s.params.loop.energy_ledger);
  EXPECT_EQ(s.scalar, vines::host::Scalar::kFloat);
  EXPECT_DOUBLE_EQ(s.output.rate_hz, 250.0);
  EXPECT_FALSE(s.output.timeseries);
}

TEST(Scene, VinesInitialStateAndBox) {
  const Scene s = parse_scene(kBase + R"(
[vines]
law = "tsuji"
box_length_m = 3.0
initial_position_m = -0.2
initial_velocity_mps = 0.1
)",
                              "x");
  const vines::VinesParams& v = s.params.device.vines;
  EXPECT_FALSE(v.start_at_left_wall);
  EXPECT_DOUBLE_EQ(v.initial_position_m, -0.2);
  EXPECT_DOUBLE_EQ(v.initial_velocity_mps, 0.1);
  EXPECT_DOUBLE_EQ(v.box_length_m, 3.0);
  EXPECT_EQ(v.law, ContactLaw::kTsuji);
}

// ---- record search ----

// A scratch folder with one record file in it.
class RecordSearch : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vines_scene_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "scenes");
    std::ofstream(dir_ / "here.dat") << "0 0\n";
    std::ofstream(dir_ / "scenes" / "beside.dat") << "0 0\n";
    const char* env = std::getenv("VINES_GROUND_MOTIONS");
    saved_env_ = env != nullptr ? env : "";
    had_env_ = env != nullptr;
  }
  void TearDown() override {
    if (had_env_)
      setenv("VINES_GROUND_MOTIONS", saved_env_.c_str(), 1);
    else
      unsetenv("VINES_GROUND_MOTIONS");
    fs::remove_all(dir_);
  }
  fs::path dir_;
  std::string saved_env_;
  bool had_env_ = false;
};

TEST_F(RecordSearch, Order) {
  const std::string scene = (dir_ / "scenes" / "s.toml").string();
  unsetenv("VINES_GROUND_MOTIONS");
  // Absolute: as is. Scene folder. Default ground-motion folder.
  EXPECT_EQ(resolve_record_path((dir_ / "here.dat").string(), scene), (dir_ / "here.dat").string());
  EXPECT_EQ(resolve_record_path("beside.dat", scene), (dir_ / "scenes" / "beside.dat").string());
  EXPECT_EQ(resolve_record_path(kElCentro, scene),
            (fs::path(VINES_DEFAULT_GROUND_MOTIONS) / kElCentro).lexically_normal().string());
  // $VINES_GROUND_MOTIONS replaces the default folder.
  setenv("VINES_GROUND_MOTIONS", dir_.c_str(), 1);
  EXPECT_EQ(resolve_record_path("here.dat", scene), (dir_ / "here.dat").string());
  EXPECT_THROW(resolve_record_path(kElCentro, scene), SceneError);
}

TEST_F(RecordSearch, NotFoundListsPlaces) {
  setenv("VINES_GROUND_MOTIONS", (dir_ / "gm").c_str(), 1);
  const std::string scene = (dir_ / "scenes" / "s.toml").string();
  try {
    resolve_record_path("nope.dat", scene);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    for (const std::string& part :
         {std::string("nope.dat"), std::string("working directory"),
          (dir_ / "scenes" / "nope.dat").string(), (dir_ / "gm" / "nope.dat").string(),
          std::string("$VINES_GROUND_MOTIONS")})
      EXPECT_NE(msg.find(part), std::string::npos) << msg << "\nlacks: " << part;
  }
  EXPECT_THROW(resolve_record_path((dir_ / "nope.dat").string(), scene), SceneError);
}

// --record PATH: the file's own format, whatever the scene's [record] says
// (the README's example: the TMD scene, time-accel columns, on a PEER AT2).
TEST(RecordOverride, FormatComesFromTheFile) {
  const std::string gm = VINES_DEFAULT_GROUND_MOTIONS;
  const Scene tmd = load_scene(kScenes + "elcentro_tmd.toml");
  ASSERT_EQ(tmd.record.format, vines::hal::RecordFormat::kTimeAccel);
  const vines::host::Excitation kobe =
      vines::host::load_excitation(tmd, gm + "/kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2");
  EXPECT_DOUBLE_EQ(kobe.record.dt_s, 0.02);  // the AT2 header: NPTS = 7500, DT = .020
  EXPECT_EQ(kobe.record.accel_mps2.size(), 7500u);
  // And the other way: a scene reading an AT2 file, given the columns file.
  Scene at2 = tmd;
  at2.record.format = vines::hal::RecordFormat::kAt2;
  const vines::host::Excitation cols = vines::host::load_excitation(at2, gm + "/" + kElCentro);
  EXPECT_EQ(cols.record.accel_mps2.size(), 2688u);
  EXPECT_DOUBLE_EQ(cols.record.dt_s, 0.02);
}

// A scene edited as a toml++ table (study overrides) is checked like a file:
// the key set takes effect, a bad value is refused naming the key, and the
// keys that came from the file keep their line.
TEST(SceneTable, EditedTableIsCheckedLikeAFile) {
  toml::table t = vines::host::read_scene_table(kScenes + "elcentro_vines.toml");
  t["vines"].as_table()->insert_or_assign("beta", 1.5);
  const Scene s = vines::host::scene_from_table(t, "edited.toml");
  EXPECT_EQ(s.params.device.vines.beta, 1.5);
  EXPECT_EQ(s.path, "edited.toml");
  t["vines"].as_table()->insert_or_assign("beta", 0.5);
  try {
    vines::host::scene_from_table(t, "edited.toml");
    FAIL() << "accepted beta = 0.5";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("edited.toml: vines.beta: "), std::string::npos) << e.what();
  }
  t["vines"].as_table()->insert_or_assign("law", "nope");
  t["vines"].as_table()->insert_or_assign("beta", 1.5);
  EXPECT_THROW(vines::host::scene_from_table(t, "edited.toml"), SceneError);
}

}  // namespace
