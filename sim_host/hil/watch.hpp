// What watches a run while it happens (the monitoring page, sim_host/monitor/):
// told of the bench before the first sample, of each sample's telemetry as it
// comes back, and of the report at the end. Called on the bench's thread: an
// observer must return at once (it copies what it needs and never waits).
#pragma once

#include "sim_host/hil/bench.hpp"
#include "sim_host/hil/record.hpp"
#include "sim_host/hil/report.hpp"

namespace vines::host {

class HilWatch {
 public:
  virtual ~HilWatch() = default;
  // The bench ready, before the node starts.
  virtual void start(const Bench& /*b*/) {}
  // Sample k's telemetry is in rec (rec.tel[k], rec.got[k]; hybrid: the
  // table and the load cell at k). Samples may come back out of order,
  // again after a restart, or not at all.
  virtual void step(long long /*k*/, const HilRecord& /*rec*/) {}
  // The run scored.
  virtual void finish(const HilReport& /*r*/) {}
};

}  // namespace vines::host
