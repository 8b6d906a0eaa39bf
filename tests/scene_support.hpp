// Shared by the scene tests (test_scene*.cpp): the shipped scenes' folder, a
// valid VI NES scene to edit, a shipped scene's text with loop lines added,
// and the refusal of a scene text.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>

#include "sim_host/scene/scene.hpp"

namespace vines::scene_test {

using vines::ContactLaw;
using vines::DampingRule;
using vines::DeviceKind;
using vines::host::load_scene;
using vines::host::parse_scene;
using vines::host::resolve_record_path;
using vines::host::Scene;
using vines::host::SceneError;
namespace fs = std::filesystem;

inline const std::string kScenes = std::string(VINES_SOURCE_DIR) + "/data/scenes/";
inline const char* kElCentro = "elcentro_1940_ns_2688pts_dt002_time_g.dat";

// A valid VI NES scene; tests append or replace parts of it.
inline const std::string kBase = R"(
[device]
kind = "vines"
[record]
path = "elcentro_1940_ns_2688pts_dt002_time_g.dat"
)";

// A shipped scene's text with `loop_lines` put first in its [loop] table.
inline std::string shipped_scene_with(const std::string& file, const std::string& loop_lines) {
  std::ifstream in(kScenes + file);
  std::stringstream all;
  all << in.rdbuf();
  std::string text = all.str();
  const auto at = text.find("[loop]\n");
  EXPECT_NE(at, std::string::npos) << file;
  return at == std::string::npos ? text : text.insert(at + 7, loop_lines);
}

// The SceneError message of parsing `text` ("" if it parses).
inline std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "bad.toml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// Expects `text` to be refused with a message containing every part.
inline void expect_refused(const std::string& text, std::initializer_list<const char*> parts) {
  const std::string msg = error_of(text);
  ASSERT_FALSE(msg.empty()) << "accepted:\n" << text;
  for (const char* p : parts) EXPECT_NE(msg.find(p), std::string::npos) << msg << "\nlacks: " << p;
}

}  // namespace vines::scene_test
