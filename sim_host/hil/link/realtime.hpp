// Real-time service from the OS for the bench and its host node (`vines hil
// --realtime-priority N --cpus B,N`, `vines node --realtime-priority N --cpu
// C`): the SCHED_FIFO policy at a priority, the memory locked (mlockall: no
// page fault in a step), the process pinned to one core. Each is asked for
// and what the OS granted, or why it refused, is reported rather than
// failing the run: a laptop without privilege still runs, and says so.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace vines::host {

struct RealtimeRequest {
  int priority = 0;  // SCHED_FIFO priority 1..99; 0: no request
  int cpu = -1;      // the core to pin to; -1: none
  bool any() const { return priority > 0 || cpu >= 0; }
};

// What one process has: its policy and priority, locked memory, its cores.
struct RealtimeGrant {
  std::string policy = "other";     // "fifo", "rr" or "other"
  int priority = 0;
  bool memory_locked = false;
  std::vector<int> cpus;            // the cores it may run on
  std::vector<std::string> refused; // what was asked and refused, with the OS's reason
};

// Asks for r for this process; what it then has.
RealtimeGrant ask_realtime(const RealtimeRequest& r);

// r for this process while it lives: its policy, affinity and memory as
// they were restored at the end (a bench run inside a longer program).
class RealtimeScope {
 public:
  explicit RealtimeScope(const RealtimeRequest& r);
  ~RealtimeScope();
  RealtimeScope(const RealtimeScope&) = delete;
  RealtimeScope& operator=(const RealtimeScope&) = delete;
  const RealtimeGrant& grant() const { return grant_; }

 private:
  RealtimeRequest asked_;
  RealtimeGrant before_, grant_;
};

// What process pid has (a child that asked for itself): its scheduling, its
// affinity, and VmLck of /proc/PID/status; refused lists what of r it lacks.
RealtimeGrant realtime_of(pid_t pid, const RealtimeRequest& r);

// "fifo 80, memory locked, cpu 1" and what was refused.
std::string describe(const RealtimeGrant& g);
nlohmann::json to_json(const RealtimeGrant& g);

}  // namespace vines::host
