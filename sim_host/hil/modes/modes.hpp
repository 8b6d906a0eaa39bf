// The bench's modes as types: replay (the node against the offline run),
// twin (the node's digital twin fed the measured building's top-floor
// acceleration) and hybrid (the node's frame drives a shake table carrying
// the VI NES; the table's load cell feeds the force back). Each sets up its
// inputs, takes part in each step, and writes its part of the report.
#pragma once

#include <memory>
#include <vector>

#include "sim_host/hil/bench.hpp"
#include "sim_host/hil/record.hpp"
#include "sim_host/hil/report.hpp"
#include "vines/link/messages.hpp"

namespace vines::host {

class BenchMode {
 public:
  virtual ~BenchMode() = default;
  // Before sample k is sent (hybrid: the table moves a period, the load cell reads).
  virtual void drive(long long /*k*/, HilRecord* /*rec*/) {}
  // The aux channel of sample k's frame (twin: measured acceleration; hybrid: measured force).
  virtual double aux(long long /*k*/, const HilRecord& /*rec*/) const { return 0.0; }
  // The measured table displacement in sample k's frame (hybrid only).
  virtual double table_x(long long /*k*/, const HilRecord& /*rec*/) const { return 0.0; }
  // The measured floor accelerations in sample k's frame (twin estimator);
  // their count.
  virtual int floors(long long /*k*/, double* /*y*/) const { return 0; }
  // Telemetry of the run came back (hybrid: the table's next command).
  virtual void on_telemetry(const link::Telemetry& /*t*/) {}
  // The mode's part of the report.
  virtual void report(const HilRecord& /*rec*/, const std::vector<link::Telemetry>& /*offline*/,
                      HilReport* /*r*/) const {}
  // The mode's own columns of --csv (none by default).
  virtual CsvColumns csv_columns(const HilRecord& /*rec*/) const { return {}; }
};

// The bench's mode set up: twin runs the measured building, hybrid builds the
// lab from the offline run's initial state.
std::unique_ptr<BenchMode> make_mode(const Bench& b, const std::vector<link::Telemetry>& offline);

// The twin mode (hil_twin_mode.cpp).
std::unique_ptr<BenchMode> make_twin_mode(const Bench& b);

}  // namespace vines::host
