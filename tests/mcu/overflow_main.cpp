// Stack-overflow image: recurses until the process stack runs into the MPU
// guard below it. Passes (ctest) only if the MemManage handler reports the
// fault; if the recursion ever returned, or the data above the stacks was
// overwritten, it says so.
#include <cstdint>

#include "semihost.h"

namespace {

volatile std::uint32_t g_sentinel = 0x5EA1C0DEu;  // .data, above the stacks

std::uint32_t dive(std::uint32_t depth) {
  volatile std::uint8_t frame[256];
  frame[depth % sizeof frame] = static_cast<std::uint8_t>(depth);
  return dive(depth + 1) + frame[(depth * 7u) % sizeof frame];
}

}  // namespace

int main() {
  const std::uint32_t r = dive(0);
  vines_semihost_puts(g_sentinel == 0x5EA1C0DEu ? "vines mcu overflow: recursion returned\n"
                                                : "vines mcu overflow: data corrupted\n");
  return static_cast<int>(r | 1u);
}
