// vines: command-line front end of the VI NES firmware model.
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include "sim_host/cli/cli.hpp"
#include "sim_host/bench.hpp"
#include "sim_host/design.hpp"
#include "sim_host/engine.hpp"
#include "sim_host/hil.hpp"
#include "sim_host/names.hpp"
#include "sim_host/reference/report.hpp"
#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"
#include "sim_host/stress.hpp"
#include "sim_host/sweep.hpp"
#include "sim_host/sweep_mpi.hpp"
#include "vines/model_image.hpp"

int main(int argc, char** argv) {
  // Commands not yet on CLI11 (sim_host/cli/).
  if (argc > 1) {
    const std::string cmd = argv[1];
    const std::vector<std::string> args(argv + 2, argv + argc);
    if (cmd == "node") return vines::host::node_main(args);
  }
  using namespace vines::cli;
  CLI::App vines("vines - Vibro-Impact Nonlinear Energy Sink firmware model (host build)", "vines");
  vines.footer("Records are looked up as given, next to the scene file, then in $VINES_GROUND_MOTIONS (default: "
               "../shared/data/ground_motions beside the repository).");
  vines.require_subcommand(1);
  // An option given twice: the last one counts.
  vines.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  use_vines_help(vines);
  add_run(vines);
  add_image(vines);
  add_reference(vines);
  add_sweep(vines);
  add_design(vines);
  add_bench(vines);
  add_stress(vines);
  add_hil(vines);
  add_help(vines);
  try {
    vines.parse(argc, argv);
    return kOk;
  } catch (const CLI::RuntimeError& e) {  // a command's own exit status
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    return report_parse_error(vines, e);
  } catch (const std::exception& e) {  // refused input
    std::fprintf(stderr, "vines %s: %s\n", vines.get_subcommands().front()->get_name().c_str(), e.what());
    return kRefused;
  }
}
