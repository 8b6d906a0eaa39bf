// The one loop of every host run: the HAL's ground source
// (vines/hal/ground_source.hpp; on the host a RecordSource over an
// excitation's samples) feeds an engine at the sensor rate, as a board's link
// feeds its node. vines run, sweep, design, bench and stress, the HIL bench's
// truth and offline run, and the Python package's run all go through drive().
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>

#include "vines/hal/ground_source.hpp"

namespace vines::host {

// Samples handed to the target per call between two stop checks (4 s of a
// 1 kHz record, milliseconds of work: a Ctrl-C is seen at once).
inline constexpr std::size_t kDriveBlock = 4096;

// Feeds every sample of `src` to `target`: the first to init(a), the others
// to run(a, n) in blocks (an engine's run() is its step() loop, bit for bit).
// With `every` > 0, observe(k) is called after sample k whenever k % every
// == 0 (k = 0: after init). A set *stop ends the feed between blocks. Returns
// the number of samples fed. Target: init(double), run(const double*, size_t).
template <typename Target, typename Observe>
std::size_t drive(Target& target, hal::GroundSource& src, std::size_t every, Observe&& observe,
                  const std::atomic<bool>* stop = nullptr) {
  double buf[kDriveBlock];
  if (!src.next(buf)) return 0;
  target.init(buf[0]);
  std::size_t k = 0;
  if (every > 0) observe(k);
  for (;;) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) break;
    const std::size_t want = every > 0 ? std::min(kDriveBlock, every - k % every) : kDriveBlock;
    const std::size_t n = src.read(buf, want);
    if (n == 0) break;
    target.run(buf, n);
    k += n;
    if (every > 0 && k % every == 0) observe(k);
    if (n < want) break;
  }
  return k + 1;
}

// drive() with nothing observed.
template <typename Target>
std::size_t drive(Target& target, hal::GroundSource& src, const std::atomic<bool>* stop = nullptr) {
  return drive(target, src, 0, [](std::size_t) {}, stop);
}

}  // namespace vines::host
