// What a physical STM32F405 board needs that QEMU's netduinoplus2 does not
// model (stm32f405_board.cpp): the clock tree, USART1's pins, its baud.
#pragma once

#include <cstdint>

namespace vines::hal::stm32f405 {

inline constexpr std::uint32_t kCoreHz = 168000000u;  // SYSCLK (QEMU's from reset)
inline constexpr std::uint32_t kApb2Hz = kCoreHz / 2;  // USART1's clock
inline constexpr std::uint32_t kLinkBaud = 3000000u;   // what a 10-story node at 1 kHz needs

// Brings the core to kCoreHz and USART1 to its pins (a physical board's
// build: VINES_STM32F405_PHYSICAL); in QEMU's build only the clock enables
// and pin modes, which QEMU ignores.
void board_init();

// USART1's BRR for kLinkBaud from kApb2Hz, 16x oversampling.
constexpr std::uint32_t usart1_brr() { return (kApb2Hz + kLinkBaud / 2) / kLinkBaud; }

}  // namespace vines::hal::stm32f405
