// Scenes refused at load because no run could keep them (docs/model.md 7.8):
// a Hertz contact shorter than the sub-steps the loop may take, an overlap
// deeper than the sphere; scene files that are not regular files or too big;
// and data/scenes/README.md against the code (every key, every default).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "sim_host/scene/limits.hpp"
#include "sim_host/scene/scene.hpp"

#include "scene_support.hpp"

namespace {

using namespace vines::scene_test;

// A VI NES scene with these [device] keys, [vines] keys and [loop] keys.
std::string vines_scene(const std::string& device, const std::string& vines, const std::string& loop = "") {
  return "[device]\nkind = \"vines\"\n" + device + "\n[vines]\n" + vines + "\n[loop]\n" + loop +
         "\n[record]\npath = \"a.dat\"\n";
}

// ---- contact time under the smallest sub-steps ----

// The particle of 1e-9 kg: t_c = 0.22 us against 0.24 us sub-steps.
TEST(SceneLimits, TinyParticleMassIsRefusedNamingTheKeys) {
  expect_refused(vines_scene("mass_kg = 1e-9", ""),
                 {"bad.toml:3:", "device.mass_kg", "Hertz contact lasts", "vines.young_pa", "loop.sensor_rate_hz",
                  "loop.max_substeps_per_step 4096", "no run can resolve"});
}

TEST(SceneLimits, TinyRadiusIsRefused) {
  expect_refused(vines_scene("", "radius_m = 1e-6"), {"vines.radius_m", "Hertz contact lasts", "radius 1e-06 m"});
}

// The rule follows the cap: a particle that passes at the default cap is
// refused with a cap of 16, and the bounded scheme names its own budget.
TEST(SceneLimits, TheCapAndTheBudgetSetTheLimit) {
  const std::string ok = vines_scene("mass_kg = 1e-3", "");
  EXPECT_EQ(error_of(ok), "");
  expect_refused(vines_scene("mass_kg = 1e-3", "", "max_substeps_per_step = 16"),
                 {"device.mass_kg", "loop.max_substeps_per_step 16"});
  expect_refused(vines_scene("mass_kg = 1e-3", "", "contact_scheme = \"bounded\""),
                 {"device.mass_kg", "loop.bounded_substeps 6"});
  // A faster sensor makes the sub-steps shorter: the same particle passes.
  EXPECT_EQ(error_of(vines_scene("mass_kg = 1e-3", "", "max_substeps_per_step = 16\nsensor_rate_hz = 1e5")), "");
}

// Restitution has no contact time: the same particle is not refused.
TEST(SceneLimits, RestitutionHasNoContactTime) {
  EXPECT_EQ(error_of(vines_scene("mass_kg = 1e-9", "law = \"restitution\"")), "");
}

// ---- overlap deeper than the sphere ----

TEST(SceneLimits, SoftMaterialIsRefusedByItsOverlap) {
  expect_refused(vines_scene("", "young_pa = 1"),
                 {"bad.toml:", "vines.young_pa", "Hertz overlap", "deeper than the radius"});
  expect_refused(vines_scene("", "wall_young_pa = 1"), {"vines.wall_young_pa", "deeper than the radius"});
  // A fast initial velocity deepens the overlap past the radius too (the
  // issue's initial_velocity_mps = 1e6 on steel: 180 m).
  EXPECT_EQ(error_of(vines_scene("", "young_pa = 1e7")), "");
  expect_refused(vines_scene("", "young_pa = 1e7\ninitial_velocity_mps = 100"), {"vines.young_pa", "at 100 m/s"});
  expect_refused(vines_scene("", "initial_velocity_mps = 1e6"), {"vines.young_pa", "Hertz overlap", "at 1e+06 m/s"});
}

// Every shipped scene passes, the default particle with a wide margin.
TEST(SceneLimits, ShippedScenesPass) {
  for (const auto& entry : fs::directory_iterator(kScenes)) {
    if (entry.path().extension() != ".toml") continue;
    const Scene s = load_scene(entry.path().string());
    EXPECT_FALSE(vines::host::check_contact_scales(s.params).has_value()) << entry.path();
  }
}

// ---- scene files: regular and bounded ----

TEST(SceneFile, DevicesFoldersAndBigFilesAreRefused) {
  auto refusal = [](const std::string& path) {
    try {
      load_scene(path);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refusal("/dev/zero").find("/dev/zero: not a regular file"), std::string::npos) << refusal("/dev/zero");
  EXPECT_NE(refusal(kScenes).find("is a directory"), std::string::npos);
  const std::string dir = ::testing::TempDir() + "scene_file_" + std::to_string(::getpid());
  fs::create_directories(dir);
  const std::string fifo = dir + "/fifo.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(refusal(fifo).find("not a regular file"), std::string::npos);
  const std::string big = dir + "/big.toml";
  std::ofstream(big) << "# " << std::string(vines::host::kMaxSceneBytes, 'x') << "\n";
  EXPECT_NE(refusal(big).find("larger than the 1048576 bytes"), std::string::npos) << refusal(big);
  fs::remove_all(dir);
}

// ---- data/scenes/README.md matches the code ----

// The README's example scene (its ```toml block).
std::string readme_block() {
  std::ifstream in(kScenes + "README.md");
  std::stringstream all;
  all << in.rdbuf();
  const std::string text = all.str();
  const auto begin = text.find("```toml\n"), end = text.find("```", begin + 8);
  return text.substr(begin + 8, end - begin - 8);
}

// Every key the reader knows (from its "unknown key (known: ...)" message)
// is written in the example, as a key or a commented key.
TEST(SceneReadme, ListsEveryKey) {
  const std::string block = readme_block();
  for (const char* table : {"scene", "frame", "device", "tmd", "vines", "record", "loop", "output", "damage"}) {
    const std::string record = std::string(table) == "record" ? "" : "[record]\npath = \"a\"\n";
    const std::string msg = error_of("[" + std::string(table) + "]\nzz_unknown = 1\n" + record);
    const auto at = msg.find("(known: ");
    ASSERT_NE(at, std::string::npos) << msg;
    std::stringstream keys(msg.substr(at + 8, msg.size() - at - 9));
    std::string key;
    while (std::getline(keys >> std::ws, key, ',')) {
      const std::regex line("\\n(# )?" + key + " = ");
      EXPECT_TRUE(std::regex_search(block, line)) << "[" << table << "] " << key << " is not in data/scenes/README.md";
    }
  }
}

// The example, as written, gives the same parameters as a scene that leaves
// every key out: the defaults it shows are the code's.
TEST(SceneReadme, DefaultsAreTheCodes) {
  const Scene readme = parse_scene(readme_block(), "README.md");
  const Scene bare = parse_scene(kBase, "base.toml");
  const vines::SceneParams &a = readme.params, &b = bare.params;
  EXPECT_EQ(a.frame.stiffness_damping_s, b.frame.stiffness_damping_s);
  EXPECT_EQ(a.frame.modal_zeta, b.frame.modal_zeta);
  EXPECT_EQ(a.frame.rayleigh_zeta[1], b.frame.rayleigh_zeta[1]);
  EXPECT_EQ(a.device.mass_ratio, b.device.mass_ratio);
  const vines::VinesParams &v = a.device.vines, &w = b.device.vines;
  for (auto [x, y] : {std::pair{v.density_kg_m3, w.density_kg_m3}, {v.young_pa, w.young_pa}, {v.poisson, w.poisson},
                      {v.wall_young_pa, w.wall_young_pa}, {v.wall_poisson, w.wall_poisson}, {v.beta, w.beta},
                      {v.eps, w.eps}, {v.v_ref_mps, w.v_ref_mps}, {v.initial_velocity_mps, w.initial_velocity_mps}})
    EXPECT_EQ(x, y);
  EXPECT_EQ(v.law, w.law);
  const vines::LoopParams &l = a.loop, &m = b.loop;
  EXPECT_EQ(l.sensor_rate_hz, m.sensor_rate_hz);
  EXPECT_EQ(l.contact_rtol, m.contact_rtol);
  EXPECT_EQ(l.max_substeps_per_step, m.max_substeps_per_step);
  EXPECT_EQ(l.contact_count_depth_m, m.contact_count_depth_m);
  EXPECT_EQ(l.energy_ledger, m.energy_ledger);
  EXPECT_EQ(l.floor_peaks, m.floor_peaks);
  EXPECT_EQ(l.divergence_limit_m, m.divergence_limit_m);
  EXPECT_EQ(l.contact_scheme, m.contact_scheme);
  EXPECT_EQ(l.bounded_substeps, m.bounded_substeps);
  EXPECT_EQ(l.split_steps, m.split_steps);
  const vines::FixedParams &f = a.fixed, &g = b.fixed;
  EXPECT_EQ(f.accel_mps2, g.accel_mps2);
  EXPECT_EQ(f.amplification, g.amplification);
  EXPECT_EQ(f.contact_speed_mps, g.contact_speed_mps);
  EXPECT_EQ(readme.scalar, bare.scalar);
  EXPECT_EQ(readme.record.format, bare.record.format);
  EXPECT_EQ(readme.record.units, bare.record.units);
  EXPECT_EQ(readme.record.scale, bare.record.scale);
  EXPECT_EQ(readme.output.rate_hz, bare.output.rate_hz);
  EXPECT_EQ(readme.output.timeseries, bare.output.timeseries);
}

}  // namespace
