// `vines node`: the firmware application (firmware/app/node_app.hpp: the
// link node around a plant, timed by the deadline monitor) on the host's HAL
// port, stdin/stdout; `vines hil` runs it as a child process. The board runs
// the same application over its UART (firmware/app/node_main.cpp).
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/node_app.hpp"
#include "sim_host/hil.hpp"
#include "sim_host/hil_plant.hpp"

namespace vines::host {

int node_main(const std::vector<std::string>& args) {
  app::ServeOptions o;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--realtime") {
      o.realtime = true;
    } else if (args[i] == "--idle-timeout" && i + 1 < args.size()) {
      char* end = nullptr;
      const double s = std::strtod(args[++i].c_str(), &end);
      if (*end != '\0' || !(s > 0 && s <= 4e6)) {
        std::fprintf(stderr, "vines node: --idle-timeout takes seconds in (0, 4e6], got %s\n", args[i].c_str());
        return 2;
      }
      o.idle_limit_ms = static_cast<std::uint32_t>(s * 1e3 + 0.5);
    } else {
      std::fprintf(stderr, "vines node: unknown argument %s\n(usage: vines node [--realtime] [--idle-timeout S])\n",
                   args[i].c_str());
      return 2;
    }
  }
  using Timed = app::TimedPlant<HostPlant>;
  auto plant = std::make_unique<HostPlant>();
  auto timed = std::make_unique<Timed>(plant.get());
  app::PortSink sink;
  auto node = std::make_unique<link::Node<Timed, app::PortSink>>(timed.get(), &sink);
  hal::port_init();
  return app::serve(*node, sink, o);
}

}  // namespace vines::host
