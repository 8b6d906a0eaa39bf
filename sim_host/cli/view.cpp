// `vines view RUN`: a finished `vines hil --csv` run on the monitoring page.
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "sim_host/cli/cli.hpp"
#include "sim_host/cli/serve.hpp"

namespace vines::cli {

void add_view(CLI::App& vines) {
  struct ViewArgs {
    std::string run;
    std::string serve = "8037";
    double for_s = 0;
  };
  auto a = std::make_shared<ViewArgs>();
  CLI::App* cmd = add_command(
      vines, "view",
      "A finished `vines hil` run on the monitoring page: its --csv replayed as the live page showed it (the same "
      "series and samples), served until Ctrl-C.",
      "The page is read-only and bound to 127.0.0.1 unless --serve names another address; at most 4 clients.",
      [a] {
        // The run read first: a bad one is refused before anything listens.
        ServedPage page;
        page.load(a->run);
        page.listen("vines view", a->serve);
        const std::atomic<bool>* stop = stop_on_interrupt("vines view", "");
        const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(a->for_s);
        while (!*stop && (a->for_s == 0 || std::chrono::steady_clock::now() < end))
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        page.stop(std::chrono::milliseconds(0));
        return kOk;
      });
  cmd->add_option("RUN", a->run, "the run's --csv file, or a folder holding it (its only .csv)")->required();
  add_serve(*cmd, &a->serve, "where the page is served: [HOST:]PORT (default 8037, on 127.0.0.1; PORT 0: any free one)");
  cmd->add_option("--for", a->for_s, "serve S seconds, then exit (default: until Ctrl-C)")
      ->type_name("S")
      ->check(number_in(0, 1e7));
}

}  // namespace vines::cli
