// `vines node`: the firmware application (firmware/app/node_app.hpp: the
// link node around a plant, timed by the deadline monitor) on the host's HAL
// port, stdin/stdout; `vines hil` runs it as a child process. The board runs
// the same application over its UART (firmware/app/node_main.cpp).
#include <cstdint>
#include <memory>

#include "firmware/app/node_app.hpp"
#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/modes/plant.hpp"

namespace vines::host {

int node_main(bool realtime, double idle_timeout_s) {
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

}  // namespace vines::host
