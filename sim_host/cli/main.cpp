// vines: command-line front end of the VI NES firmware model. The commands are
// in sim_host/cli/, one file each; this builds the app from them and turns what
// happened into the exit status (cli.hpp: 0, 1 refused input, 2 usage, 3
// degraded results, 130).
#include <csignal>
#include <cstdio>
#include <exception>

#include "sim_host/cli/cli.hpp"
#include "sim_host/io/printable.hpp"

int main(int argc, char** argv) {
  using namespace vines::cli;
  // A file-size limit (ulimit -f) is a write error like a full disk: the write
  // fails with EFBIG, named with its file (exit 1), instead of SIGXFSZ
  // killing the process and leaving its temporary file.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App vines("vines - Vibro-Impact Nonlinear Energy Sink firmware model (host build)", "vines");
  vines.footer("Records are looked up as given, next to the scene file, then in $VINES_GROUND_MOTIONS (default: "
               "../shared/data/ground_motions beside the repository).\nExit status: 0 done, 1 refused input or a "
               "failed run, 2 usage error, 3 finished but a result is degraded (--accept-degraded: 0), 130 Ctrl-C.");
  vines.require_subcommand(1);
  // An option given twice: the last one counts.
  vines.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  use_vines_help(vines);
  add_run(vines);
  add_sweep(vines);
  add_design(vines);
  add_bench(vines);
  add_reference(vines);
  add_stress(vines);
  add_hil(vines);
  add_image(vines);
  add_node(vines);
  add_view(vines);
  add_help(vines);
  try {
    vines.parse(argc, argv);
    return kOk;
  } catch (const CLI::RuntimeError& e) {  // a command's own exit status
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    return report_parse_error(vines, e);
  } catch (const std::exception& e) {  // refused input
    std::fprintf(stderr, "vines %s: %s\n", vines.get_subcommands().front()->get_name().c_str(),
                 vines::host::printable(e.what()).c_str());
    return kRefused;
  }
}
