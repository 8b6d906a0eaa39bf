#include "sim_host/hil/link/realtime.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

namespace vines::host {
namespace {

std::string why(int e) {
  std::string s = std::strerror(e);
  if (e == EPERM)
    s += " (no privilege: run as root, give the program CAP_SYS_NICE and CAP_IPC_LOCK, or raise rtprio and "
         "memlock in /etc/security/limits.conf)";
  return s;
}

RealtimeGrant observe(pid_t pid) {
  RealtimeGrant g;
  const int policy = ::sched_getscheduler(pid);
  g.policy = policy == SCHED_FIFO ? "fifo" : policy == SCHED_RR ? "rr" : "other";
  sched_param p{};
  if (::sched_getparam(pid, &p) == 0) g.priority = p.sched_priority;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::sched_getaffinity(pid, sizeof set, &set) == 0)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) g.cpus.push_back(c);
  std::ifstream status("/proc/" + std::to_string(pid == 0 ? ::getpid() : pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmLck:", 0) == 0) g.memory_locked = std::stol(line.substr(6)) > 0;
  return g;
}

// What of r the grant lacks, as it was refused (reason: the OS's, or "").
void lacks(const RealtimeRequest& r, const std::string& reason, RealtimeGrant* g) {
  auto add = [&](const std::string& what) { g->refused.push_back(what + (reason.empty() ? "" : ": " + reason)); };
  if (r.priority > 0 && (g->policy != "fifo" || g->priority != r.priority))
    add("SCHED_FIFO priority " + std::to_string(r.priority));
  if (r.priority > 0 && !g->memory_locked) add("locked memory");
  if (r.cpu >= 0 && (g->cpus.size() != 1 || g->cpus[0] != r.cpu)) add("core " + std::to_string(r.cpu));
}

}  // namespace

RealtimeGrant ask_realtime(const RealtimeRequest& r) {
  std::vector<std::string> refused;
  if (r.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (r.cpu < CPU_SETSIZE) CPU_SET(r.cpu, &set);
    if (r.cpu >= CPU_SETSIZE || ::sched_setaffinity(0, sizeof set, &set) != 0)
      refused.push_back("core " + std::to_string(r.cpu) + ": " +
                        (r.cpu >= CPU_SETSIZE || errno == EINVAL ? std::string("no such core on this machine (") +
                                                                       std::to_string(::sysconf(_SC_NPROCESSORS_ONLN)) +
                                                                       " online)"
                                                                 : why(errno)));
  }
  if (r.priority > 0) {
    if (::mlockall(MCL_CURRENT | MCL_FUTURE) != 0) refused.push_back("locked memory: " + why(errno));
    const sched_param p{r.priority};
    if (::sched_setscheduler(0, SCHED_FIFO, &p) != 0)
      refused.push_back("SCHED_FIFO priority " + std::to_string(r.priority) + ": " + why(errno));
  }
  RealtimeGrant g = observe(0);
  g.refused = refused;
  return g;
}

RealtimeScope::RealtimeScope(const RealtimeRequest& r) : asked_(r), before_(observe(0)) {
  if (r.any()) grant_ = ask_realtime(r);
}

RealtimeScope::~RealtimeScope() {
  if (!asked_.any()) return;
  if (asked_.priority > 0) {
    const sched_param p{before_.priority};
    ::sched_setscheduler(0, before_.policy == "fifo" ? SCHED_FIFO : before_.policy == "rr" ? SCHED_RR : SCHED_OTHER, &p);
    if (!before_.memory_locked) ::munlockall();
  }
  if (asked_.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int c : before_.cpus) CPU_SET(c, &set);
    ::sched_setaffinity(0, sizeof set, &set);
  }
}

RealtimeGrant realtime_of(pid_t pid, const RealtimeRequest& r) {
  RealtimeGrant g = observe(pid);
  lacks(r, "", &g);
  return g;
}

std::string describe(const RealtimeGrant& g) {
  std::string s = g.policy == "other" ? "time-shared" : "SCHED_" + std::string(g.policy == "fifo" ? "FIFO" : "RR") +
                                                            " " + std::to_string(g.priority);
  s += g.memory_locked ? ", memory locked" : ", memory not locked";
  if (g.cpus.size() == 1) s += ", core " + std::to_string(g.cpus[0]);
  else s += ", any of " + std::to_string(g.cpus.size()) + " cores";
  for (const std::string& r : g.refused) s += "; refused: " + r;
  return s;
}

nlohmann::json to_json(const RealtimeGrant& g) {
  return {{"policy", g.policy},
          {"priority", g.priority},
          {"memory_locked", g.memory_locked},
          {"cpus", g.cpus},
          {"refused", g.refused}};
}

}  // namespace vines::host
