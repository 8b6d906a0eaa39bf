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
  const std::atomic<bool>* stop = nullptr;  // once set, no job starts (those under way stop: Stopped)
  bool progress = false;                    // a bar on a TTY, else about ten lines
  std::string label = "sweep", unit = "runs";  // "LABEL: 3/40 UNIT, ..." lines
};

// Thrown by a job that sees the stop flag part way (stop_point): the job is
// dropped and the map ends. Not a std::exception, so that the catch-alls
// that turn errors into a run's message let it through.
struct Stopped {};

// Throws Stopped once *stop is set (no-op for a null flag). Long loops call
// it every few hundred steps so that Ctrl-C is answered within a second.
inline void stop_point(const std::atomic<bool>* stop) {
  if (stop != nullptr && stop->load(std::memory_order_relaxed)) throw Stopped{};
}

// The threads a map with `requested` threads (0: all cores) runs on.
int map_threads(int requested);

// Calls job(i) for every i in [0, n) (fewer once opt.stop is set; a job
// that throws Stopped is dropped). Any other exception a job throws stops
// the map and is rethrown here.
void parallel_map(std::size_t n, const MapOptions& opt, const std::function<void(std::size_t)>& job);

}  // namespace vines::host
