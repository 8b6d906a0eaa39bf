// What the bench's tests share (test_hil.cpp, test_hil_tcp.cpp,
// test_hil_serial.cpp): the El Centro VI NES scene, the options of a run
// against this build's node, and a fault's run over a link against the pipes.
#pragma once

#include <gtest/gtest.h>

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

// Fault kind k at samples 700, 1400 and 2100 of a 3 s run over `link` (a
// TCP or serial node) and over the pipes: each detected and survived, and
// the same run (every output, each fault's effect).
inline void expect_fault_as_over_pipes(const HilOptions& link, FaultKind k) {
  HilOptions o = base(3.0), t = link;
  o.faults[static_cast<int>(k)] = t.faults[static_cast<int>(k)] = parse_fault_spec("--x", "@700,1400,2100");
  const HilReport p = run_hil(vines_scene(), o), r = run_hil(vines_scene(), t);
  const char* name = fault_kind_name(k);
  SCOPED_TRACE(name);
  ASSERT_EQ(r.faults.count(name), 1u);
  EXPECT_EQ(r.faults.at(name).detected, 3);
  EXPECT_EQ(r.faults.at(name).survived, 3);
  EXPECT_TRUE(r.survived);
  EXPECT_EQ(r.bit_exact, p.bit_exact);
  EXPECT_EQ(r.max_deviation_from_offline, p.max_deviation_from_offline);
  EXPECT_EQ(r.faults.at(name).deviation_m, p.faults.at(name).deviation_m);
  EXPECT_EQ(r.node_faults, p.node_faults);
  EXPECT_EQ(r.node_restarts, p.node_restarts);
  EXPECT_EQ(r.steps, p.steps);
}

}  // namespace vines::host
