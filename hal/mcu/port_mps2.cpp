// MCU backend of vines/hal/port.hpp for the MPS2 boards (AN386, AN500): the
// CMSDK APB peripherals at the same addresses on both (QEMU hw/arm/mps2.c).
//   UART0  0x40004000  samples in / telemetry out, polled (1-byte buffers)
//   TIMER0 0x40000000  sensor tick, IRQ 8
//   TIMER1 0x40001000  free-running down-counter at the 25 MHz APB clock
#include <cstdint>

#include "semihost.h"
#include "vines/hal/port.hpp"

namespace {

constexpr std::uint32_t kPclkHz = 25000000u;  // MPS2 SYSCLK (APB clock of the timers)
constexpr std::uint32_t kLinkTimeoutS = 2u;  // a silent link is an error, not a hang

struct Uart {
  volatile std::uint32_t data, state, ctrl, intstatus, bauddiv;
};
struct Timer {
  volatile std::uint32_t ctrl, value, reload, intclear;
};
enum : std::uint32_t {
  kTxFull = 1u << 0, kRxFull = 1u << 1, kRxOverrun = 1u << 3,  // UART STATE
  kTxEn = 1u << 0, kRxEn = 1u << 1,                            // UART CTRL
  kTimerEnable = 1u << 0, kTimerIrqEnable = 1u << 3,           // TIMER CTRL
};

Uart& uart0() { return *reinterpret_cast<Uart*>(0x40004000u); }
Timer& timer0() { return *reinterpret_cast<Timer*>(0x40000000u); }
Timer& timer1() { return *reinterpret_cast<Timer*>(0x40001000u); }
volatile std::uint32_t& nvic_iser0() { return *reinterpret_cast<volatile std::uint32_t*>(0xE000E100u); }

constexpr std::uint32_t kPaint = 0xA5A5A5A5u;

volatile bool g_tick_pending = false;
volatile std::uint32_t g_ticks_missed = 0;
const char* g_error = "";

}  // namespace

extern "C" std::uint32_t __stack_limit[], __stack_top[];  // mps2_sections.ld

// Timer 0's interrupt (vector table slot IRQ 8, startup.c).
extern "C" void TIMER0_Handler(void) {
  timer0().intclear = 1u;
  if (g_tick_pending) ++g_ticks_missed;
  g_tick_pending = true;
}

namespace vines::hal {

void port_init() {
  uart0().bauddiv = kPclkHz / 115200u;  // >= 16, else QEMU reports a bad baud rate
  uart0().ctrl = kTxEn | kRxEn;
  timer1().reload = 0xFFFFFFFFu;
  timer1().value = 0xFFFFFFFFu;
  timer1().ctrl = kTimerEnable;
}

bool link_read(void* dst, std::size_t n) {
  auto* p = static_cast<std::uint8_t*>(dst);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t start = counter_now();
    while (!(uart0().state & kRxFull)) {
      if (counter_now() - start > kLinkTimeoutS * kPclkHz) {
        g_error = "UART0: no byte for 2 s (the stream ended or stalled)";
        return false;
      }
    }
    if (uart0().state & kRxOverrun) {
      g_error = "UART0 receive overrun (a byte was lost)";
      return false;
    }
    p[i] = static_cast<std::uint8_t>(uart0().data);
  }
  return true;
}

void link_write(const void* src, std::size_t n) {
  const auto* p = static_cast<const std::uint8_t*>(src);
  for (std::size_t i = 0; i < n; ++i) {
    while (uart0().state & kTxFull) {
    }
    uart0().data = p[i];
  }
}

const char* port_error() { return g_error; }

void console_write(const char* text) { vines_semihost_puts(text); }

bool tick_start(double rate_hz) {
  const double period = static_cast<double>(kPclkHz) / rate_hz;
  if (!(period >= 16.0 && period <= 4.0e9)) return false;
  timer0().reload = static_cast<std::uint32_t>(period + 0.5) - 1u;
  timer0().value = timer0().reload;
  timer0().ctrl = kTimerEnable | kTimerIrqEnable;
  nvic_iser0() = 1u << 8;
  return true;
}

void wait_tick() {
  // Check and sleep with interrupts masked, so a tick between the check and
  // the WFI still wakes it (WFI wakes on a pending interrupt even when masked).
  __asm__ volatile("cpsid i" ::: "memory");
  while (!g_tick_pending) {
    __asm__ volatile("wfi\n\tcpsie i\n\tisb\n\tcpsid i" ::: "memory");
  }
  g_tick_pending = false;
  __asm__ volatile("cpsie i" ::: "memory");
}

std::uint32_t ticks_missed() { return g_ticks_missed; }

std::uint32_t counter_now() { return ~timer1().value; }  // counts up
std::uint32_t counter_hz() { return kPclkHz; }

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
