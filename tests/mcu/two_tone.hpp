// What the fixed-point images (fixed_main.cpp, fixed_vines_main.cpp) share:
// their ground motion, a tone at the frame's first mode plus a faster one,
// sampled at 1 kHz, and the line each prints of a step's cost.
#pragma once

#include <cmath>
#include <cstdint>

#include "semihost.h"

namespace vines::mcu {

// Sample k [m/s^2]: `first` m/s^2 at 0.5 Hz (near the first mode) plus 1 m/s^2 at 2.1 Hz.
inline double two_tone(long k, double first) {
  const double t = static_cast<double>(k) * 1e-3;
  return first * std::sin(2 * 3.14159265358979 * 0.5 * t) + 1.0 * std::sin(2 * 3.14159265358979 * 2.1 * t);
}

// "WHAT: instructions/step max W, mean M" from timer ticks (timer 1 at
// 25 MHz under QEMU -icount shift=3: 5 instructions per tick).
inline void put_step_cost(const char* what, std::uint32_t worst, std::uint64_t total, long steps) {
  vines_semihost_puts(what);
  vines_semihost_puts(": instructions/step max ");
  vines_semihost_put_int(static_cast<long long>(worst) * 5);
  vines_semihost_puts(", mean ");
  vines_semihost_put_int(static_cast<long long>(total * 5 / static_cast<std::uint64_t>(steps)));
  vines_semihost_puts("\n");
}

}  // namespace vines::mcu
