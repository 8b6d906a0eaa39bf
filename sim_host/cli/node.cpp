// `vines node`: the firmware node on stdin/stdout (what `vines hil` runs), or
// on TCP or a serial line for a bench elsewhere (--listen).
#include <memory>
#include <stdexcept>
#include <string>

#include "sim_host/cli/cli.hpp"
#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/link/realtime.hpp"
#include "sim_host/hil/link/serial.hpp"
#include "sim_host/hil/link/tcp.hpp"

namespace vines::cli {

void add_node(CLI::App& vines) {
  struct NodeArgs {
    bool realtime = false;
    double idle_timeout_s = 30;
    std::string listen;
    host::RealtimeRequest rt;
  };
  auto a = std::make_shared<NodeArgs>();
  CLI::App* cmd =
      add_command(vines, "node",
                  "The firmware node on stdin/stdout (what `vines hil` runs; protocol in docs/link_protocol.md).", "",
                  [a] { return host::node_main(a->realtime, a->idle_timeout_s, a->listen, a->rt); });
  cmd->add_flag("--realtime", a->realtime, "deadlines on the local clock (default: the samples' stamps)");
  cmd->add_option("--idle-timeout", a->idle_timeout_s, "give up after S seconds without a byte (default 30)")
      ->type_name("S")
      ->check(positive_up_to(4e6));
  cmd->add_option_function<std::string>(
         "--listen",
         [a](const std::string& v) {
           try {
             if (host::is_serial(v)) host::parse_serial_address(v);
             else host::parse_tcp_address(v, "127.0.0.1", true);
           } catch (const std::runtime_error& e) {
             throw CLI::ValidationError("--listen", e.what());
           }
           a->listen = v;
         },
         "wait for a bench on TCP instead (`vines hil ... --node tcp:HOST:PORT`): one at a time, each a fresh "
         "node, until killed; HOST 127.0.0.1 unless given (0.0.0.0: every interface; the link has no "
         "authentication, keep it on a lab network); PORT 0: a free one; or on a serial line, raw 8N1 (default "
         "3000000 baud), a fresh node for each bench's run; prints where it listens")
      ->type_name("tcp:[HOST:]PORT|serial:DEVICE[@BAUD]");
  CLI::Option* serial = cmd->add_option_function<std::string>(
                               "--serial",
                               [a](const std::string& v) {
                                 try {
                                   host::parse_serial_address("serial:" + v);
                                 } catch (const std::runtime_error& e) {
                                   throw CLI::ValidationError("--serial", e.what());
                                 }
                                 a->listen = "serial:" + v;
                               },
                               "the same as --listen serial:DEVICE[@BAUD]")
                            ->type_name("DEVICE[@BAUD]");
  serial->excludes(cmd->get_option("--listen"));
  cmd->add_option("--realtime-priority", a->rt.priority,
                  "SCHED_FIFO at priority N with the memory locked (what the OS refuses is said on stderr)")
      ->type_name("N")
      ->check(CLI::Range(1, 99));
  cmd->add_option("--cpu", a->rt.cpu, "pinned to core C")->type_name("C")->check(CLI::Range(0, 1023));
}

}  // namespace vines::cli
