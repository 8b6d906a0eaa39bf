// The STM32F405's set-up that QEMU's netduinoplus2 does not model and a
// physical board needs (ST RM0090): the one file of the port where QEMU and
// the chip differ (docs/boards.md says what is emulated).
//
// - Pins: USART1 on PA9 (TX) and PA10 (RX), alternate function 7, their
//   clocks on. Always written: QEMU ignores these registers.
// - Clock tree, only with VINES_STM32F405_PHYSICAL (a physical board's build,
//   -DVINES_STM32F405_PHYSICAL=ON): from reset the chip runs on its 16 MHz
//   internal oscillator; this brings the crystal (kHseHz: set it to the
//   board's), the PLL to 168 MHz (VCO 336 MHz, 48 MHz for USB), the flash's
//   five wait states, APB1 at 42 MHz and APB2 at 84 MHz. QEMU's SYSCLK is
//   168 MHz from reset and its RCC reads as zeros, so there the ready flags
//   never rise: the QEMU build leaves the clock tree alone. Not run on a chip
//   here: a physical board's first bring-up checks it with a scope on PA8
//   (MCO1) or by the link's baud.
#include "stm32f405_board.hpp"

#include <cstdint>

#include "vines/hal/port.hpp"

namespace vines::hal::stm32f405 {
namespace {

std::uint32_t volatile& reg(std::uint32_t address) { return *reinterpret_cast<std::uint32_t volatile*>(address); }

constexpr std::uint32_t kRcc = 0x40023800u, kFlash = 0x40023C00u, kGpioA = 0x40020000u;
constexpr std::uint32_t kRccCr = kRcc + 0x00, kRccPllcfgr = kRcc + 0x04, kRccCfgr = kRcc + 0x08;
constexpr std::uint32_t kRccAhb1enr = kRcc + 0x30, kRccApb2enr = kRcc + 0x44;
constexpr std::uint32_t kGpioModer = kGpioA + 0x00, kGpioOspeedr = kGpioA + 0x08, kGpioPupdr = kGpioA + 0x0C;
constexpr std::uint32_t kGpioAfrh = kGpioA + 0x24;

#if VINES_STM32F405_PHYSICAL
constexpr std::uint32_t kHseHz = 8000000u;  // the board's crystal

// Waits for a flag, at most ~10^6 polls (tens of ms at 16 MHz).
bool wait_for(std::uint32_t address, std::uint32_t mask, std::uint32_t value) {
  for (std::uint32_t i = 0; i < 1000000u; ++i)
    if ((reg(address) & mask) == value) return true;
  return false;
}

void clock_tree() {
  reg(kRccCr) |= 1u << 16;  // HSEON
  if (!wait_for(kRccCr, 1u << 17, 1u << 17)) {
    console_write("vines stm32f405: the crystal did not start: the node's clock is wrong\n");
    return;
  }
  reg(kFlash) = 5u | (1u << 8) | (1u << 9) | (1u << 10);  // 5 wait states, prefetch, caches
  reg(kRccPllcfgr) = (kHseHz / 1000000u)                   // PLLM: 1 MHz into the PLL
                     | (336u << 6)                          // PLLN: VCO 336 MHz
                     | (0u << 16)                           // PLLP /2: 168 MHz
                     | (1u << 22)                           // from the crystal
                     | (7u << 24);                          // PLLQ /7: 48 MHz
  reg(kRccCr) |= 1u << 24;  // PLLON
  if (!wait_for(kRccCr, 1u << 25, 1u << 25)) {
    console_write("vines stm32f405: the PLL did not lock: the node's clock is wrong\n");
    return;
  }
  reg(kRccCfgr) = (5u << 10) | (4u << 13) | 2u;  // APB1 /4, APB2 /2, SYSCLK from the PLL
  if (!wait_for(kRccCfgr, 3u << 2, 2u << 2)) console_write("vines stm32f405: SYSCLK did not switch to the PLL\n");
}
#endif

}  // namespace

void board_init() {
#if VINES_STM32F405_PHYSICAL
  clock_tree();
#endif
  reg(kRccAhb1enr) |= 1u << 0;  // GPIOA
  reg(kRccApb2enr) |= 1u << 4;  // USART1
  reg(kGpioModer) = (reg(kGpioModer) & ~(0xFu << 18)) | (0xAu << 18);  // PA9, PA10: alternate function
  reg(kGpioOspeedr) |= 0xFu << 18;                                      // very high speed (3 Mbaud)
  reg(kGpioPupdr) = (reg(kGpioPupdr) & ~(0x3u << 20)) | (0x1u << 20);   // RX pulled up: an idle line
  reg(kGpioAfrh) = (reg(kGpioAfrh) & ~(0xFFu << 4)) | (0x77u << 4);     // AF7: USART1
}

}  // namespace vines::hal::stm32f405
