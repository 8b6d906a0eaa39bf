// `vines node`: the firmware application (firmware/app/node_app.hpp: the
// link node around a plant, timed by the deadline monitor) on the host's HAL
// port, stdin/stdout; `vines hil` runs it as a child process. With
// --listen tcp:[HOST:]PORT it waits for a bench on TCP instead, and serves
// one bench at a time on that connection, each a fresh node (a bench that
// cut the link, as a power cut does, finds a cold node when it comes back);
// with --listen serial:DEVICE[@BAUD], on a serial line, a fresh node each
// time a bench's bytes arrive after the last one's run ended.
// The board runs the same application over its UART (firmware/app/node_main.cpp).
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "firmware/app/node_app.hpp"
#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/link/realtime.hpp"
#include "sim_host/hil/link/serial.hpp"
#include "sim_host/hil/link/tcp.hpp"
#include "sim_host/hil/modes/plant.hpp"

namespace vines::host {
namespace {

int serve_link(bool realtime, double idle_timeout_s) {
  app::ServeOptions o;
  o.realtime = realtime;
  o.idle_limit_ms = static_cast<std::uint32_t>(idle_timeout_s * 1e3 + 0.5);
  using Timed = app::TimedPlant<HostPlant>;
  auto plant = std::make_unique<HostPlant>();
  auto timed = std::make_unique<Timed>(plant.get());
  app::PortSink sink;
  auto node = std::make_unique<link::Node<Timed, app::PortSink>>(timed.get(), &sink);
  hal::port_init();
  node->announce();  // as a board does once its UART is on: the bench waits for it
  return app::serve(*node, sink, o);
}

// Puts fd on stdin and stdout (the host port's link), or /dev/null there.
void link_on(int fd) {
  const int use = fd >= 0 ? fd : ::open("/dev/null", O_RDWR | O_CLOEXEC);
  ::dup2(use, 0);
  ::dup2(use, 1);
  ::close(use);
}

// Waits until the line has bytes to read (a bench began): true; false when
// it hung up or failed (the adapter pulled, the far end of a pty gone).
bool await_bench(int fd) {
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, -1);
    if (r < 0 && errno != EINTR) return false;
    if (r > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL))) return false;
    if (r > 0 && (p.revents & POLLIN)) return true;
  }
}

int serve_serial(bool realtime, double idle_timeout_s, const std::string& listen) {
  const SerialAddress a = parse_serial_address(listen);
  const int fd = open_serial(a, "--listen");
  // Blocking reads from here on: the host port polls before it reads.
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  std::printf("vines node: listening on serial:%s\n", to_string(a).c_str());
  std::fflush(stdout);
  for (;;) {
    if (!await_bench(fd)) {
      std::fprintf(stderr, "vines node: serial:%s: the line hung up\n", to_string(a).c_str());
      return 1;
    }
    link_on(::dup(fd));
    const int rc = serve_link(realtime, idle_timeout_s);
    link_on(-1);
    std::fprintf(stderr, "vines node: the bench's run ended%s; listening again\n",
                 rc == 0 ? "" : " (silent beyond --idle-timeout, or the line broke)");
  }
}

}  // namespace

int node_main(bool realtime, double idle_timeout_s, const std::string& listen, const RealtimeRequest& rt) {
  // Real-time service first, before the node's memory is touched; what the
  // OS refused is said, and the bench reads what was granted from /proc.
  if (rt.any())
    for (const std::string& r : ask_realtime(rt).refused) std::fprintf(stderr, "vines node: refused: %s\n", r.c_str());
  if (listen.empty()) return serve_link(realtime, idle_timeout_s);
  if (is_serial(listen)) return serve_serial(realtime, idle_timeout_s, listen);
  const TcpAddress a = parse_tcp_address(listen, "127.0.0.1", true);
  int port = 0;
  const int listener = listen_tcp(a, &port);
  // Where it listens, on stdout before the link takes it over (port 0: the
  // port the system chose); a bench reaches it with --node tcp:HOST:PORT.
  std::printf("vines node: listening on tcp:%s\n", to_string(TcpAddress{a.host, port}).c_str());
  std::fflush(stdout);
  ::signal(SIGPIPE, SIG_IGN);  // a bench gone shows as EPIPE on the next write
  for (;;) {
    const int fd = accept_bench(listener);
    if (fd < 0) {
      std::fprintf(stderr, "vines node: accept: %s\n", std::strerror(errno));
      ::close(listener);
      return 1;
    }
    link_on(fd);
    const int rc = serve_link(realtime, idle_timeout_s);
    link_on(-1);
    std::fprintf(stderr, "vines node: the bench's link ended%s; listening again\n",
                 rc == 0 ? "" : " (idle beyond --idle-timeout, or broken)");
  }
}

}  // namespace vines::host
