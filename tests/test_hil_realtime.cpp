// `vines hil --realtime --realtime-priority N --cpus B,N`: the bench and its
// host node ask the OS for SCHED_FIFO, locked memory and a core each; the
// report says what each got, read back from the OS (the node's from /proc),
// and what was refused with the reason; the bench's process is as before
// once the run ends; a core that does not exist is refused by name.
#include <gtest/gtest.h>

#include <sched.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "sim_host/hil/hil.hpp"
#include "hil_support.hpp"

namespace vines::host {
namespace {

bool refused(const RealtimeGrant& g, const std::string& what) {
  return std::any_of(g.refused.begin(), g.refused.end(), [&](const std::string& r) { return r.rfind(what, 0) == 0; });
}

// Each request either granted, as the OS reports it, or refused by name.
void expect_granted_or_refused(const RealtimeGrant& g, int priority, int cpu) {
  EXPECT_TRUE((g.policy == "fifo" && g.priority == priority) || refused(g, "SCHED_FIFO priority 10"))
      << describe(g);
  EXPECT_TRUE(g.memory_locked || refused(g, "locked memory")) << describe(g);
  EXPECT_TRUE((g.cpus.size() == 1 && g.cpus[0] == cpu) || refused(g, "core " + std::to_string(cpu))) << describe(g);
}

TEST(HilRealtime, WhatWasAskedIsGrantedOrRefusedByNameAndTheBenchRestored) {
  cpu_set_t before;
  ASSERT_EQ(::sched_getaffinity(0, sizeof before, &before), 0);
  HilOptions o = base(1.0);
  o.realtime = true;
  o.rt_priority = 10;
  o.cpus = {0, 1};
  const HilReport r = run_hil(vines_scene(), o);
  ASSERT_TRUE(r.bench_service && r.node_service);
  expect_granted_or_refused(*r.bench_service, 10, 0);
  expect_granted_or_refused(*r.node_service, 10, 1);
  EXPECT_EQ(r.steps, r.samples);
  // The bench's process as it was: time-shared, on its cores, memory free.
  EXPECT_EQ(::sched_getscheduler(0), SCHED_OTHER);
  cpu_set_t after;
  ASSERT_EQ(::sched_getaffinity(0, sizeof after, &after), 0);
  EXPECT_TRUE(CPU_EQUAL(&before, &after));
  // A core this machine does not have: the node's pinning refused, named.
  o.cpus = {0, 1000};
  const HilReport far = run_hil(vines_scene(), o);
  ASSERT_TRUE(far.node_service);
  EXPECT_TRUE(refused(*far.node_service, "core 1000")) << describe(*far.node_service);
}

TEST(HilRealtime, ServiceOnTheVirtualClockIsRefused) {
  HilOptions o = base(1.0);
  o.rt_priority = 10;
  try {
    run_hil(vines_scene(), o);
    ADD_FAILURE() << "ran real-time service on the virtual clock";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--realtime-priority: real-time service is for a run on the wall clock"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace vines::host
