// HAL facade: the board services the firmware loop needs besides the core.
// This header only declares; one backend defines, chosen at build time (a
// Pigweed-style facade: the build links exactly one of them):
//   MCU  hal/mcu/port_mps2.cpp  CMSDK APB UART0 (samples in, telemetry out),
//                               CMSDK APB timer 0 (sensor tick, interrupt),
//                               CMSDK APB timer 1 (free-running counter)
//   host hal/host/port.cpp      stdin/stdout, a simulated tick, steady_clock
// No heap, no exceptions; callable from the firmware's translation units.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vines::hal {

// Brings up the link and the counter. Call once, first.
void port_init();

// Reads exactly n bytes of the link into dst (blocking). False if the link
// ended or failed before n bytes came (the backend says why in port_error()).
bool link_read(void* dst, std::size_t n);
// Writes n bytes to the link (blocking).
void link_write(const void* src, std::size_t n);
// Why the last link_read failed ("" if it did not).
const char* port_error();

// Diagnostics for the person running the image (MCU: semihosting; host:
// stderr). Test I/O only: never on the sample path.
void console_write(const char* text);

// Starts the sensor tick at rate_hz; wait_tick() returns once per tick. A
// tick that comes while the previous one is still unconsumed is counted as
// missed (the loop fell behind the sensor).
bool tick_start(double rate_hz);
void wait_tick();
std::uint32_t ticks_missed();

// Free-running counter (wraps; differences of two readings are exact while
// under 2^32 counts) and its rate.
std::uint32_t counter_now();
std::uint32_t counter_hz();

// Stack high-water mark: stack_paint() fills the unused part of the stack
// with a pattern (call it first thing in main); stack_peak_bytes() is the
// deepest the stack has been since, measured from its top (host: 0, unknown).
void stack_paint();
std::uint32_t stack_peak_bytes();

// Interrupts off/on around a measured section, so that no handler's
// instructions are counted in it (no-ops on the host).
void irq_off();
void irq_on();

}  // namespace vines::hal
