// `vines node`: the firmware node (link/node.hpp) on the host, speaking the
// link protocol on stdin/stdout; `vines hil` runs it as a child process.
// Exits at end of input, or after --idle-timeout seconds without a byte.
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "sim_host/hil.hpp"
#include "sim_host/hil_plant.hpp"
#include "vines/link/node.hpp"

namespace vines::host {
namespace {

struct FdSink {
  int fd = 1;
  bool broken = false;
  void write(const std::uint8_t* p, std::size_t n) {
    while (n > 0 && !broken) {
      const ssize_t w = ::write(fd, p, n);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        broken = true;
        return;
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
  }
};

std::uint64_t local_ns() {
  static const auto t0 = std::chrono::steady_clock::now();
  return 1 + static_cast<std::uint64_t>(
                 std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace

int node_main(const std::vector<std::string>& args) {
  bool realtime = false;
  double idle_s = 30;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--realtime") {
      realtime = true;
    } else if (args[i] == "--idle-timeout" && i + 1 < args.size()) {
      char* end = nullptr;
      idle_s = std::strtod(args[++i].c_str(), &end);
      if (*end != '\0' || !(idle_s > 0)) {
        std::fprintf(stderr, "vines node: --idle-timeout takes seconds > 0, got %s\n", args[i].c_str());
        return 2;
      }
    } else {
      std::fprintf(stderr, "vines node: unknown argument %s\n(usage: vines node [--realtime] [--idle-timeout S])\n",
                   args[i].c_str());
      return 2;
    }
  }
  auto plant = std::make_unique<HostPlant>();
  FdSink sink;
  using HostNode = link::Node<HostPlant, FdSink>;
  auto node = std::make_unique<HostNode>(plant.get(), &sink);
  std::uint8_t buf[4096];
  auto last_byte = std::chrono::steady_clock::now();
  while (!sink.broken) {
    int timeout_ms = 100;
    if (realtime) {
      const std::uint64_t next = node->next_deadline_local(), now = local_ns();
      if (next != UINT64_MAX) timeout_ms = next <= now ? 0 : static_cast<int>(std::min<std::uint64_t>(100, (next - now) / 1000000 + 1));
    }
    pollfd p{0, POLLIN, 0};
    const int r = ::poll(&p, 1, timeout_ms);
    if (r < 0 && errno != EINTR) break;
    if (r > 0) {
      const ssize_t n = ::read(0, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;  // end of input: the bench is done
      last_byte = std::chrono::steady_clock::now();
      for (ssize_t i = 0; i < n; ++i) node->on_byte(buf[i], realtime ? local_ns() : 0);
    } else if (std::chrono::duration<double>(std::chrono::steady_clock::now() - last_byte).count() > idle_s) {
      std::fprintf(stderr, "vines node: no input for %.0f s, exiting\n", idle_s);
      return 1;
    }
    if (realtime) node->poll(local_ns());
  }
  return 0;
}

}  // namespace vines::host
