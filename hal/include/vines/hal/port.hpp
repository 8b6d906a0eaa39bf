// HAL facade: the board services the firmware application needs besides the
// core. This header only declares; one backend defines, chosen at build time
// (a Pigweed-style facade: the build links exactly one of them):
//   MCU  hal/mcu/port_mps2.cpp  CMSDK APB UART0 (the link),
//                               CMSDK APB timer 1 (free-running counter)
//   host hal/host/port.cpp      stdin/stdout, steady_clock
// No heap, no exceptions; callable from the firmware's translation units.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vines::hal {

// Brings up the link and the counter. Call once, first.
void port_init();

// link_getc: the next byte of the link (0-255), waiting at most timeout_ms;
// kLinkIdle if none came in that time, kLinkClosed once the link has ended
// or failed (port_error() says why).
inline constexpr int kLinkIdle = -1, kLinkClosed = -2;
int link_getc(std::uint32_t timeout_ms);
// Writes n bytes to the link (blocking); false if the link is gone.
bool link_write(const void* src, std::size_t n);
// Why the link closed ("" if it did not).
const char* port_error();

// Diagnostics for the person running the image (MCU: semihosting; host:
// stderr). Test I/O only: never on the sample path.
void console_write(const char* text);

// Free-running counter (wraps; differences of two readings are exact while
// under 2^32 counts) and its rate.
std::uint32_t counter_now();
std::uint32_t counter_hz();
// Monotonic local time [ns] since an arbitrary origin, never 0. The MCU
// extends the 32-bit counter: call it at least once per counter wrap
// (171 s at 25 MHz); the application's loop does.
std::uint64_t time_ns();

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
