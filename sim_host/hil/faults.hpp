// The bench's fault plan: which samples get which fault, drawn once from the
// options (rates with a seeded generator, or given samples), one fault per
// sample (the first kind in FaultKind's order that hits it) and none inside
// another fault's window. A rate r hits each sample with probability r; a
// drawn fault leaves one free sample after its window, a certain one (listed,
// or rate 1) does not, so a rate of 1 hits every sample after the first.
#pragma once

#include <vector>

#include "sim_host/hil/options.hpp"

namespace vines::host {

struct FaultEvent {
  FaultKind kind = FaultKind::kDrop;
  long long k = 0;    // first sample affected
  int span = 1;       // samples it covers (stall: S; late: L periods of delay)
  // Filled while running:
  long long life = 0;          // which node process it hit
  std::vector<unsigned> seqs;  // link sequence numbers of its frames (drop, corrupt, duplicate, reorder)
  bool detected = false, survived = false;
};

// Faults for samples 1 .. samples-1, in sample order. Windows that would run
// past the end are not placed.
std::vector<FaultEvent> plan_faults(const HilOptions& opt, long long samples);

}  // namespace vines::host
