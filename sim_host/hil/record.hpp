// What the bench keeps of a run, sample by sample: what it sent, what came
// back and when, and what the node reported. The scorer (hil_score.hpp), the
// modes' results (hil_modes.hpp) and the CSV (hil_report.hpp) read it.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "sim_host/hil/link/realtime.hpp"
#include "vines/link/messages.hpp"

namespace vines::host {

struct HilRecord {
  // lab: keep the hybrid mode's table and load cell too.
  HilRecord(long long count, bool lab)
      : samples(count), sensed(n()), clipped(n(), 0), tel(n()), got(n(), 0), arrival(n(), 0), handled(n(), 0),
        sent(n(), 0), sent_life(n(), -1), tel_life(n(), -1), table_x(lab ? n() : 0, 0), force(lab ? n() : 0, 0) {}

  // Sample k's latency [s]: its telemetry's arrival minus the sending of its
  // frame, when the node stepped it from that frame (not held, not
  // interpolated) in the same life; none otherwise.
  std::optional<double> latency(long long k) const {
    const auto i = static_cast<std::size_t>(k);
    if (!got[i] || tel_life[i] != sent_life[i] || (tel[i].flags & (link::kInterpolated | link::kHeld)))
      return std::nullopt;
    return arrival[i] - sent[i];
  }

  long long samples;
  // The samples as the sensor gives them (clipped at its range), and which were clipped.
  std::vector<double> sensed;
  std::vector<char> clipped;
  // Telemetry by step, whether it came, its arrival and when its sample was
  // handled (bench clock, s).
  std::vector<link::Telemetry> tel;
  std::vector<char> got;
  std::vector<double> arrival, handled;
  // Each sample's first sending to a node, that node's life (-1: never sent),
  // and the life of the node whose telemetry it is (a restart starts life+1).
  std::vector<double> sent;
  std::vector<long long> sent_life, tel_life;
  // The node's fault messages and the node process (life) each came from.
  std::vector<link::Fault> faults;
  std::vector<long long> fault_life;
  // Hybrid only (empty otherwise): the table's position and the load cell's force.
  std::vector<double> table_x, force;
  long long bad_frames = 0, restarts = 0;
  link::Status final_status;
  int node_exit = 0;
  double wall_s = 0;
  // Real-time service asked for (--realtime-priority, --cpus): what the
  // bench got, and the host node (none for a node elsewhere).
  std::optional<RealtimeGrant> bench_service, node_service;

 private:
  std::size_t n() const { return static_cast<std::size_t>(samples); }
};

}  // namespace vines::host
