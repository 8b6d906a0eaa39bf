// One parallel map for the commands that run many independent jobs (sweep,
// design, stress): oneTBB on a fixed number of threads, with progress on
// stderr and a stop flag (Ctrl-C). Each job writes its own slot of a result
// vector, by index, so results do not depend on the thread count or order.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

namespace vines::host {

struct MapOptions {
  int threads = 0;                          // 0: all cores (map_threads)
  const std::atomic<bool>* stop = nullptr;  // once set, no job starts (those under way finish)
  bool progress = false;                    // a bar on a TTY, else about ten lines
  std::string label = "sweep", unit = "runs";  // "LABEL: 3/40 UNIT, ..." lines
};

// The threads a map with `requested` threads (0: all cores) runs on.
int map_threads(int requested);

// Calls job(i) for every i in [0, n) (fewer once opt.stop is set). An
// exception a job throws stops the map and is rethrown here.
void parallel_map(std::size_t n, const MapOptions& opt, const std::function<void(std::size_t)>& job);

}  // namespace vines::host
