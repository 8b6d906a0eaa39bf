// MCU backend of vines/hal/port.hpp for the MPS2 boards (AN385, AN386,
// AN500): the CMSDK APB peripherals at the same addresses on all three (QEMU
// hw/arm/mps2.c); port_cortex_m.cpp has the parts every board shares.
//   UART0  0x40004000  the link (frames in and out), polled (1-byte buffers)
//   TIMER1 0x40001000  free-running down-counter at the 25 MHz APB clock
#include <cstdint>

#include "vines/hal/port.hpp"

namespace {

constexpr std::uint32_t kPclkHz = 25000000u;  // MPS2 SYSCLK (APB clock of the timers)

struct Uart {
  volatile std::uint32_t data, state, ctrl, intstatus, bauddiv;
};
struct Timer {
  volatile std::uint32_t ctrl, value, reload, intclear;
};
enum : std::uint32_t {
  kTxFull = 1u << 0, kRxFull = 1u << 1, kRxOverrun = 1u << 3,  // UART STATE
  kTxEn = 1u << 0, kRxEn = 1u << 1,                            // UART CTRL
  kTimerEnable = 1u << 0,                                      // TIMER CTRL
};

Uart& uart0() { return *reinterpret_cast<Uart*>(0x40004000u); }
Timer& timer1() { return *reinterpret_cast<Timer*>(0x40001000u); }

const char* g_error = "";

}  // namespace

namespace vines::hal {

void port_init() {
  uart0().bauddiv = kPclkHz / 115200u;  // >= 16, else QEMU reports a bad baud rate
  uart0().ctrl = kTxEn | kRxEn;
  timer1().reload = 0xFFFFFFFFu;
  timer1().value = 0xFFFFFFFFu;
  timer1().ctrl = kTimerEnable;
}

int link_getc(std::uint32_t timeout_ms) {
  const std::uint32_t start = counter_now(), limit = timeout_ms * (kPclkHz / 1000u);
  while (!(uart0().state & kRxFull)) {
    if (counter_now() - start > limit) return kLinkIdle;
  }
  // A lost byte costs the frame around it, which the protocol detects (CRC):
  // clear the overrun and go on.
  if (uart0().state & kRxOverrun) uart0().state = kRxOverrun;
  return static_cast<int>(uart0().data & 0xFFu);
}

bool link_write(const void* src, std::size_t n) {
  const auto* p = static_cast<const std::uint8_t*>(src);
  for (std::size_t i = 0; i < n; ++i) {
    while (uart0().state & kTxFull) {
    }
    uart0().data = p[i];
  }
  return true;
}

const char* port_error() { return g_error; }

std::uint32_t counter_now() { return ~timer1().value; }  // counts up
std::uint32_t counter_hz() { return kPclkHz; }

}  // namespace vines::hal
