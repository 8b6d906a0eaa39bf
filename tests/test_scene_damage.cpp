// A scene's [damage] table (damage striking during the earthquake): read,
// and every bad input refused with a message naming the file, the line and
// the key.
#include <gtest/gtest.h>

#include <string>

#include "sim_host/scene/scene.hpp"

#include "scene_support.hpp"

namespace {

using namespace vines::scene_test;
using vines::host::is_scene_key;

const std::string kStory3 = "[damage]\ntime_s = 12.5\nstiffness_scales = [1, 1, 0.9, 1, 1, 1, 1, 1, 1, 1]\n";

TEST(SceneDamage, Read) {
  const Scene s = parse_scene(kBase + kStory3, "ok.toml");
  ASSERT_TRUE(s.damage.present());
  EXPECT_TRUE(s.damage.any());
  EXPECT_EQ(s.damage.time_s, 12.5);
  ASSERT_EQ(s.damage.stiffness_scales.size(), 10u);
  EXPECT_EQ(s.damage.stiffness_scales[2], 0.9);
  EXPECT_EQ(s.damage.stiffness_scales[0], 1.0);
  // The frame before the damage is the scene's own.
  EXPECT_EQ(s.params.frame.stiffness_scales[2], 1.0);
  // Integers are numbers; every factor 1 is a no-op, not an error; 0 s is the start.
  const Scene ones = parse_scene(kBase + "[damage]\ntime_s = 0\nstiffness_scales = [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n",
                                 "ok.toml");
  EXPECT_TRUE(ones.damage.present());
  EXPECT_FALSE(ones.damage.any());
  EXPECT_EQ(ones.damage.time_s, 0.0);
  EXPECT_FALSE(parse_scene(kBase, "ok.toml").damage.present());
}

// The factors multiply the frame's own (its stiffness_scales and eta_k), and
// the devices' parameters are left alone (they are designed on the undamaged frame).
TEST(SceneDamage, DamagedParams) {
  const Scene s = parse_scene(kBase + "[frame]\nstiffness_scale = 0.95\nstiffness_scales = [1, 1, 0.8, 1, 1, 1, 1, 1, 1, 1]\n" +
                                  kStory3,
                              "ok.toml");
  const vines::SceneParams p = vines::host::damaged_params(s.params, s.damage);
  EXPECT_DOUBLE_EQ(p.frame.stiffness_scales[2], 0.8 * 0.9);
  EXPECT_EQ(p.frame.stiffness_scales[3], 1.0);
  EXPECT_EQ(p.frame.stiffness_scale, 0.95);
  EXPECT_EQ(p.device.kind, s.params.device.kind);
  // No [damage]: the parameters themselves.
  const Scene none = parse_scene(kBase, "ok.toml");
  EXPECT_EQ(vines::host::damaged_params(none.params, none.damage).frame.stiffness_scales[2], 1.0);
}

TEST(SceneDamage, BothKeysRequired) {
  expect_refused(kBase + "[damage]\nstiffness_scales = [1, 1, 0.9, 1, 1, 1, 1, 1, 1, 1]\n",
                 {"bad.toml", "damage.time_s", "required"});
  expect_refused(kBase + "[damage]\ntime_s = 3\n", {"bad.toml", "damage.stiffness_scales", "required"});
  expect_refused(kBase + "[damage]\n", {"damage.time_s", "required"});
}

TEST(SceneDamage, BadTime) {
  const std::string scales = "stiffness_scales = [1, 1, 0.9, 1, 1, 1, 1, 1, 1, 1]\n";
  expect_refused(kBase + "[damage]\ntime_s = -1\n" + scales, {"bad.toml:7:", "damage.time_s", ">= 0"});
  expect_refused(kBase + "[damage]\ntime_s = nan\n" + scales, {"bad.toml:7:", "damage.time_s", "finite"});
  expect_refused(kBase + "[damage]\ntime_s = inf\n" + scales, {"damage.time_s", "finite"});
  expect_refused(kBase + "[damage]\ntime_s = \"12 s\"\n" + scales, {"damage.time_s", "must be a number"});
}

TEST(SceneDamage, BadScales) {
  const std::string t = "[damage]\ntime_s = 5\n";
  // One factor per story: Table 1 has 10; a custom frame its own count.
  expect_refused(kBase + t + "stiffness_scales = [1, 0.9]\n",
                 {"bad.toml:8:", "damage.stiffness_scales", "one factor per story (10, got 2)"});
  expect_refused(kBase + t + "stiffness_scales = []\n", {"damage.stiffness_scales", "one factor per story"});
  expect_refused(R"(
[frame]
preset = "custom"
masses_kg = [1e5]
stiffnesses_n_per_m = [4e6]
[record]
path = "a"
[damage]
time_s = 1
stiffness_scales = [0.9, 0.9]
)",
                 {"bad.toml:10:", "damage.stiffness_scales", "one factor per story (1, got 2)"});
  // Each factor finite, > 0, and not above 1 (a stiffening is not damage).
  expect_refused(kBase + t + "stiffness_scales = [1, 1, 0, 1, 1, 1, 1, 1, 1, 1]\n",
                 {"damage.stiffness_scales[2]", "finite and > 0"});
  expect_refused(kBase + t + "stiffness_scales = [1, 1, -0.5, 1, 1, 1, 1, 1, 1, 1]\n",
                 {"damage.stiffness_scales[2]", "> 0"});
  expect_refused(kBase + t + "stiffness_scales = [1, nan, 1, 1, 1, 1, 1, 1, 1, 1]\n",
                 {"damage.stiffness_scales[1]", "finite"});
  expect_refused(kBase + t + "stiffness_scales = [1, 1, 1, 1, 1, 1, 1, 1, 1, inf]\n",
                 {"damage.stiffness_scales[9]", "finite"});
  expect_refused(kBase + t + "stiffness_scales = [1, 1, 1.1, 1, 1, 1, 1, 1, 1, 1]\n",
                 {"bad.toml:8:", "damage.stiffness_scales[2]", "a factor above 1 is not damage"});
  expect_refused(kBase + t + "stiffness_scales = [1, 1, \"x\", 1, 1, 1, 1, 1, 1, 1]\n",
                 {"damage.stiffness_scales[2]", "must be a number"});
  expect_refused(kBase + t + "stiffness_scales = 0.9\n", {"damage.stiffness_scales", "must be an array"});
}

TEST(SceneDamage, TableAndKeys) {
  expect_refused(kBase + kStory3 + "story = 3\n", {"bad.toml:9:", "damage.story", "unknown key"});
  expect_refused("damage = 3\n" + kBase, {"bad.toml:1:", "damage", "must be a table"});
  EXPECT_TRUE(is_scene_key("damage.time_s"));
  EXPECT_TRUE(is_scene_key("damage.stiffness_scales"));
  EXPECT_FALSE(is_scene_key("damage.story"));
}

// A time the record never reaches is refused where the record is known:
// check_damage_time names the scene, the key, the time and the record's length.
TEST(SceneDamage, TimeOutsideTheRecord) {
  const Scene s = parse_scene(kBase + "[damage]\ntime_s = 60\nstiffness_scales = [1, 1, 0.9, 1, 1, 1, 1, 1, 1, 1]\n",
                              "late.toml");
  EXPECT_NO_THROW(vines::host::check_damage_time(s, 60.5));
  try {
    vines::host::check_damage_time(s, 53.74);
    ADD_FAILURE() << "accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    for (const char* part : {"late.toml", "damage.time_s", "60 s", "53.74 s", "never strike"})
      EXPECT_NE(m.find(part), std::string::npos) << m << "\nlacks: " << part;
  }
  // At the record's end: no step left on the damaged building.
  EXPECT_THROW(vines::host::check_damage_time(s, 60.0), SceneError);
}

}  // namespace
