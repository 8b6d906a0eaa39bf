// `vines node`: the firmware application (firmware/app/node_app.hpp: the
// link node around a plant, timed by the deadline monitor) on the host's HAL
// port, stdin/stdout; `vines hil` runs it as a child process. With
// --listen tcp:[HOST:]PORT it waits for a bench on TCP instead, and serves
// one bench at a time on that connection, each a fresh node (a bench that
// cut the link, as a power cut does, finds a cold node when it comes back).
// The board runs the same application over its UART (firmware/app/node_main.cpp).
#include <fcntl.h>
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
  return app::serve(*node, sink, o);
}

// Puts fd on stdin and stdout (the host port's link), or /dev/null there.
void link_on(int fd) {
  const int use = fd >= 0 ? fd : ::open("/dev/null", O_RDWR | O_CLOEXEC);
  ::dup2(use, 0);
  ::dup2(use, 1);
  ::close(use);
}

}  // namespace

int node_main(bool realtime, double idle_timeout_s, const std::string& listen) {
  if (listen.empty()) return serve_link(realtime, idle_timeout_s);
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
