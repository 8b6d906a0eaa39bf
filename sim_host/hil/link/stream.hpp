// The run itself: the record streamed to the node, paced on the wall clock
// (--realtime) or in lock step on the virtual clock, with the planned faults
// put on the link (frames dropped, corrupted, duplicated, reordered, late,
// stalled, non-finite samples, node restarts), and the node's answers kept.
#pragma once

#include <vector>

#include "sim_host/hil/bench.hpp"
#include "sim_host/hil/faults.hpp"
#include "sim_host/hil/modes/modes.hpp"
#include "sim_host/hil/record.hpp"
#include "sim_host/hil/watch.hpp"

namespace vines::host {

// Runs the bench from its first sample to STOP. Fills each event's node life,
// link sequence numbers and (restart) detection. Throws naming the node if
// it fails or does not answer within --timeout. The watch (if any) is told
// of each telemetry as it lands in the record.
HilRecord stream(const Bench& b, BenchMode& mode, std::vector<FaultEvent>* events, HilWatch* watch = nullptr);

}  // namespace vines::host
