// The parts of vines/hal/port.hpp's MCU backends that every Cortex-M board
// shares (port_mps2.cpp, port_stm32f405.cpp define the rest: the link, the
// counter): the local clock from the board's counter, the stack's paint and
// high-water mark (the stacks of sections.ld), interrupt masking, and the
// console over semihosting.
#include <cstdint>

#include "semihost.h"
#include "vines/hal/port.hpp"

namespace {

constexpr std::uint32_t kPaint = 0xA5A5A5A5u;

std::uint64_t g_time_ticks = 0;  // the counter extended to 64 bits by time_ns()
std::uint32_t g_time_last = 0;

}  // namespace

extern "C" std::uint32_t __stack_limit[], __stack_top[];  // sections.ld

namespace vines::hal {

void console_write(const char* text) { vines_semihost_puts(text); }

std::uint64_t time_ns() {
  const std::uint32_t now = counter_now();
  g_time_ticks += now - g_time_last;
  g_time_last = now;
  // Whole seconds and the rest apart, so that no product overflows 64 bits
  // (a tick a whole number of ns, as the MPS2's 40, needs no division).
  const std::uint64_t hz = counter_hz();
  if (1000000000u % hz == 0) return 1 + g_time_ticks * (1000000000u / hz);
  return 1 + g_time_ticks / hz * 1000000000u + g_time_ticks % hz * 1000000000u / hz;
}

void stack_paint() {
  std::uint32_t* sp;
  __asm__ volatile("mov %0, sp" : "=r"(sp));
  for (std::uint32_t* p = __stack_limit; p < sp - 16; ++p) *const_cast<volatile std::uint32_t*>(p) = kPaint;
}

std::uint32_t stack_peak_bytes() {
  const std::uint32_t* p = __stack_limit;
  while (p < __stack_top && *const_cast<const volatile std::uint32_t*>(p) == kPaint) ++p;
  return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(__stack_top) - reinterpret_cast<std::uintptr_t>(p));
}

void irq_off() { __asm__ volatile("cpsid i" ::: "memory"); }
void irq_on() { __asm__ volatile("cpsie i" ::: "memory"); }

}  // namespace vines::hal
