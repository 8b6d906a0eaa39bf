// `vines node`: the firmware node on stdin/stdout (what `vines hil` runs).
#include <memory>

#include "sim_host/cli/cli.hpp"
#include "sim_host/hil/hil.hpp"

namespace vines::cli {

void add_node(CLI::App& vines) {
  struct NodeArgs {
    bool realtime = false;
    double idle_timeout_s = 30;
  };
  auto a = std::make_shared<NodeArgs>();
  CLI::App* cmd =
      add_command(vines, "node",
                  "The firmware node on stdin/stdout (what `vines hil` runs; protocol in docs/link_protocol.md).", "",
                  [a] { return host::node_main(a->realtime, a->idle_timeout_s); });
  cmd->add_flag("--realtime", a->realtime, "deadlines on the local clock (default: the samples' stamps)");
  cmd->add_option("--idle-timeout", a->idle_timeout_s, "give up after S seconds without a byte (default 30)")
      ->type_name("S")
      ->check(positive_up_to(4e6));
}

}  // namespace vines::cli
