// What the bench keeps of a run, sample by sample: what it sent, what came
// back and when, and what the node reported. The scorer (hil_score.hpp), the
// modes' results (hil_modes.hpp) and the CSV (hil_report.hpp) read it.
#pragma once

#include <cstddef>
#include <vector>

#include "vines/link/messages.hpp"

namespace vines::host {

struct HilRecord {
  // lab: keep the hybrid mode's table and load cell too.
  HilRecord(long long count, bool lab)
      : samples(count), sensed(n()), clipped(n(), 0), tel(n()), got(n(), 0), arrival(n(), 0), handled(n(), 0),
        table_x(lab ? n() : 0, 0), force(lab ? n() : 0, 0) {}

  long long samples;
  // The samples as the sensor gives them (clipped at its range), and which were clipped.
  std::vector<double> sensed;
  std::vector<char> clipped;
  // Telemetry by step, whether it came, its arrival and when its sample was
  // handled (bench clock, s).
  std::vector<link::Telemetry> tel;
  std::vector<char> got;
  std::vector<double> arrival, handled;
  // The node's fault messages and the node process (life) each came from.
  std::vector<link::Fault> faults;
  std::vector<long long> fault_life;
  // Hybrid only (empty otherwise): the table's position and the load cell's force.
  std::vector<double> table_x, force;
  long long bad_frames = 0, restarts = 0;
  link::Status final_status;
  int node_exit = 0;
  double wall_s = 0;

 private:
  std::size_t n() const { return static_cast<std::size_t>(samples); }
};

}  // namespace vines::host
