// What the Engine's state tests share (test_loop_state.cpp,
// test_set_physical.cpp): the shipped scenes' folder, an engine built from a
// scene's parameters, a message's part, 8 s of El Centro at 1 kHz.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sim_host/engines/build_engine.hpp"
#include "support.hpp"

namespace vines::test {

inline const std::string kScenes = std::string(VINES_SOURCE_DIR) + "/data/scenes/";

inline std::unique_ptr<host::Engine> built(const SceneParams& p, host::Scalar scalar) {
  return host::build_engine(p, scalar, "test");
}

inline bool has(const std::string& msg, const char* part) { return msg.find(part) != std::string::npos; }

// The strong part of El Centro, with contacts.
inline std::vector<double> samples() {
  std::vector<double> a = elcentro(1000.0);
  a.resize(8001);
  return a;
}

}  // namespace vines::test
