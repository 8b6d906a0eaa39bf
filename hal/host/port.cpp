// Host backend of vines/hal/port.hpp: the link is stdin/stdout (binary, read
// in blocks and handed out a byte at a time), the counter is steady_clock in
// nanoseconds.
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>

#include "vines/hal/port.hpp"

namespace vines::hal {
namespace {

const char* g_error = "";
unsigned char g_in[4096];
ssize_t g_in_len = 0, g_in_pos = 0;
bool g_closed = false;

std::uint64_t steady_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count());
}

}  // namespace

// A fresh link on stdin/stdout (`vines node --listen` puts each bench's
// connection there in turn).
void port_init() {
  g_error = "";
  g_in_len = g_in_pos = 0;
  g_closed = false;
}

int link_getc(std::uint32_t timeout_ms) {
  if (g_in_pos < g_in_len) return g_in[g_in_pos++];
  if (g_closed) return kLinkClosed;
  pollfd p{0, POLLIN, 0};
  const int r = ::poll(&p, 1, static_cast<int>(timeout_ms));
  if (r < 0 && errno == EINTR) return kLinkIdle;
  if (r == 0) return kLinkIdle;
  const ssize_t n = r > 0 ? ::read(0, g_in, sizeof g_in) : -1;
  if (n < 0 && (errno == EINTR || errno == EAGAIN)) return kLinkIdle;
  if (n <= 0) {
    g_closed = true;
    g_error = n == 0 ? "stdin: end of input" : "stdin: read error";
    return kLinkClosed;
  }
  g_in_len = n;
  g_in_pos = 1;
  return g_in[0];
}

bool link_write(const void* src, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(src);
  while (n > 0) {
    const ssize_t w = ::write(1, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      g_error = "stdout: write failed (the bench is gone)";
      return false;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

const char* port_error() { return g_error; }

void console_write(const char* text) { std::fputs(text, stderr); }

std::uint32_t counter_now() { return static_cast<std::uint32_t>(steady_ns()); }
std::uint32_t counter_hz() { return 1000000000u; }
std::uint64_t time_ns() {
  static const std::uint64_t t0 = steady_ns();
  return 1 + (steady_ns() - t0);
}

void stack_paint() {}
std::uint32_t stack_peak_bytes() { return 0; }

void irq_off() {}
void irq_on() {}

}  // namespace vines::hal
