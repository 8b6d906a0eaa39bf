// MCU backend of vines/hal/port.hpp for the STM32F405 (Cortex-M4F; QEMU's
// netduinoplus2, a chip a lab can buy), written for the chip's registers
// (ST RM0090, ARMv7-M ARM):
//   USART1   0x40011000  the link (frames in and out), polled: RXNE, TXE
//   SysTick  0xE000E010  the counter: the core's clock (168 MHz), 24 bits,
//                        extended to 32 in software
// port_cortex_m.cpp has the parts every board shares; what a physical board
// needs besides (the clock tree at 168 MHz, USART1's pins, its baud) is in
// stm32f405_board.cpp, the one file where QEMU and the chip differ.
#include <cstdint>

#include "stm32f405_board.hpp"
#include "vines/hal/port.hpp"

namespace {

struct Usart {
  volatile std::uint32_t sr, dr, brr, cr1, cr2, cr3, gtpr;
};
struct SysTick {
  volatile std::uint32_t csr, rvr, cvr, calib;
};
enum : std::uint32_t {
  kRxne = 1u << 5, kTxe = 1u << 7,                  // USART SR
  kUe = 1u << 13, kTe = 1u << 3, kRe = 1u << 2,     // USART CR1
  kTickEnable = 1u << 0, kTickCoreClock = 1u << 2,  // SysTick CSR (no interrupt)
  kTickMask = 0xFFFFFFu,                            // SysTick counts 24 bits
};

Usart& usart1() { return *reinterpret_cast<Usart*>(0x40011000u); }
SysTick& systick() { return *reinterpret_cast<SysTick*>(0xE000E010u); }

const char* g_error = "";
std::uint32_t g_count = 0, g_tick_last = 0;  // the 24-bit SysTick, extended

}  // namespace

namespace vines::hal {

void port_init() {
  stm32f405::board_init();  // clocks and pins: a physical board's (QEMU models neither)
  usart1().brr = stm32f405::usart1_brr();
  usart1().cr1 = kUe | kTe | kRe;  // 8N1, 16x oversampling
  systick().rvr = kTickMask;
  systick().cvr = 0;
  systick().csr = kTickEnable | kTickCoreClock;
  g_tick_last = systick().cvr;
}

int link_getc(std::uint32_t timeout_ms) {
  const std::uint32_t start = counter_now(), limit = timeout_ms * (counter_hz() / 1000u);
  while (!(usart1().sr & kRxne)) {
    if (counter_now() - start > limit) return kLinkIdle;
  }
  // SR read, then DR: that clears an overrun too. The byte lost with it
  // costs the frame around it, which the protocol detects (CRC).
  return static_cast<int>(usart1().dr & 0xFFu);
}

bool link_write(const void* src, std::size_t n) {
  const auto* p = static_cast<const std::uint8_t*>(src);
  for (std::size_t i = 0; i < n; ++i) {
    while (!(usart1().sr & kTxe)) {
    }
    usart1().dr = p[i];
  }
  return true;
}

const char* port_error() { return g_error; }

// The SysTick counts down 24 bits at the core clock: a wrap every 99.9 ms.
// Each reading extends the count, so the application must read it at least
// that often; its loop does (link_getc polls it while it waits, and a step
// takes well under a millisecond).
std::uint32_t counter_now() {
  const std::uint32_t now = systick().cvr;
  g_count += (g_tick_last - now) & kTickMask;
  g_tick_last = now;
  return g_count;
}
std::uint32_t counter_hz() { return stm32f405::kCoreHz; }

}  // namespace vines::hal
