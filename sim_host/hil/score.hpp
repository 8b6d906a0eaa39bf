// Scoring a `vines hil` run: each planned fault detected by the node, each
// kind survived or not (and the clipped samples), deadlines and latency, the deviation
// from the offline run, the node's fault counts and its deadline monitor.
#pragma once

#include <vector>

#include "sim_host/hil/bench.hpp"
#include "sim_host/hil/faults.hpp"
#include "sim_host/hil/record.hpp"
#include "sim_host/hil/report.hpp"
#include "vines/link/messages.hpp"

namespace vines::host {

// The report of a run but the modes' parts (hil_modes.hpp); marks each event
// detected and survived. `offline` is the clean run; `reference` the clean
// run of each node life (the same without restarts), what survival is
// judged against.
HilReport score(const Bench& b, const HilRecord& rec, const std::vector<link::Telemetry>& offline,
                const std::vector<link::Telemetry>& reference, std::vector<FaultEvent>* events);

}  // namespace vines::host
