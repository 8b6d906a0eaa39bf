// What the bench's tests share (test_hil.cpp, test_hil_tcp.cpp): the El
// Centro VI NES scene and the options of a run against this build's node.
#pragma once

#include <string>

#include "sim_host/hil/hil.hpp"

namespace vines::host {

inline Scene vines_scene() { return load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines.toml"); }

// The first duration_s seconds (0: the whole record) against `vines node`.
inline HilOptions base(double duration_s) {
  HilOptions o;
  o.node_command = VINES_EXE;
  o.duration_s = duration_s;
  o.timeout_s = 20;
  return o;
}

}  // namespace vines::host
