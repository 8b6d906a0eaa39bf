// The byte stream a sample link carries into the firmware loop (UART0 on the
// MCU, stdin on the host), written by the host tool vines_feed:
//   Header | SceneParams (raw bytes) | samples (float or double, one per tick)
// and the telemetry the loop sends back (text lines, see firmware/app/loop_main.cpp).
// Little-endian on both ends (x86-64, ARM EABI); the SceneParams layout is
// checked through its size and two member offsets, so a sender built from
// other sources is refused instead of misread.
#pragma once

#include <cstddef>
#include <cstdint>

#include "vines/params.hpp"

namespace vines::hal::link {

inline constexpr char kMagic[4] = {'V', 'N', 'S', '1'};

struct Header {
  char magic[4];
  std::uint32_t params_bytes;   // sizeof(SceneParams) on the sender
  std::uint32_t params_layout;  // layout_check() on the sender
  std::uint32_t sample_bytes;   // 4: float samples, 8: double
  std::uint32_t samples;        // how many follow; sample k at t = k / sensor rate
  std::uint32_t budget_ticks;   // deadline per step in counter ticks; 0: one sensor period
};
static_assert(sizeof(Header) == 24, "the header is sent as raw bytes");

inline std::uint32_t layout_check() {
  return static_cast<std::uint32_t>(offsetof(SceneParams, device) | offsetof(SceneParams, loop) << 16);
}

}  // namespace vines::hal::link
