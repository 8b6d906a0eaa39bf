// Host backend of vines/hal/port.hpp: the link is stdin/stdout (binary), the
// sensor tick is simulated (every wait returns at once: the host runs as fast
// as it can), the counter is steady_clock in nanoseconds.
#include <chrono>
#include <cstdio>

#include "vines/hal/port.hpp"

namespace vines::hal {
namespace {
const char* g_error = "";
}  // namespace

void port_init() {}

bool link_read(void* dst, std::size_t n) {
  if (std::fread(dst, 1, n, stdin) == n) return true;
  g_error = std::ferror(stdin) ? "stdin: read error" : "stdin: ended early";
  return false;
}

void link_write(const void* src, std::size_t n) { std::fwrite(src, 1, n, stdout); }

const char* port_error() { return g_error; }

void console_write(const char* text) { std::fputs(text, stderr); }

bool tick_start(double rate_hz) { return rate_hz > 0.0; }
void wait_tick() {}
std::uint32_t ticks_missed() { return 0; }

std::uint32_t counter_now() {
  const auto ns = std::chrono::steady_clock::now().time_since_epoch();
  return static_cast<std::uint32_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(ns).count());
}
std::uint32_t counter_hz() { return 1000000000u; }

void stack_paint() {}
std::uint32_t stack_peak_bytes() { return 0; }

void irq_off() {}
void irq_on() {}

}  // namespace vines::hal
