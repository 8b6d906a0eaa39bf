// The `vines` command line on CLI11: one file per command in sim_host/cli/,
// each with an add_<command>() that registers the subcommand (its options,
// help text and checks) and what it runs; main.cpp builds the app from them.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace vines::cli {

// Exit status of every command.
inline constexpr int kOk = 0;
inline constexpr int kRefused = 1;       // refused input: bad scene or file, a run that failed
inline constexpr int kUsage = 2;         // unknown option, bad option value, missing argument
inline constexpr int kDegraded = 3;      // finished, a result degraded (hil: a fault kind not survived); --accept-degraded: 0
inline constexpr int kInterrupted = 130; // Ctrl-C

// Adds `vines NAME`: `summary` says what it does (in `vines help` and atop its
// own help), `notes` follow its options. `run` runs it once the command line is
// parsed and checked; its return value is the exit status. An exception it
// throws is refused input (main prints it, status 1), a CLI::ParseError a usage
// error (status 2).
CLI::App* add_command(CLI::App& vines, const std::string& name, const std::string& summary, const std::string& notes,
                      std::function<int()> run);

// NAME LIST: comma-separated numbers, each finite and > 0, into *out (the last
// NAME given wins); anything else is a usage error naming the option and the list.
CLI::Option* add_number_list(CLI::App& cmd, const std::string& name, std::vector<double>* out, const std::string& help);
// The same with whole numbers from lo to hi.
CLI::Option* add_number_list(CLI::App& cmd, const std::string& name, std::vector<int>* out, int lo, int hi,
                             const std::string& help);

// Checks of a number option, whose message names the value: a number from lo
// to hi (hi from 1e18 on: no upper bound but the type's); a number > 0 and at
// most hi. (CLI::Range lets NaN through.)
CLI::Validator number_in(double lo, double hi);
CLI::Validator positive_up_to(double hi);
// Check of a file or folder option (--out, --csv): not an empty path.
CLI::Validator non_empty_path();

// The exit status of finished results: kOk, or kDegraded when any is degraded
// and the user did not pass --accept-degraded.
inline int finished_status(bool degraded, bool accept_degraded) {
  return degraded && !accept_degraded ? kDegraded : kOk;
}

// Adds --accept-degraded to a command (exit 0 with degraded results).
CLI::Option* add_accept_degraded(CLI::App& cmd, bool* accept);

// Ctrl-C from now on sets the returned flag (runs under way stop at their
// next check, within a second; the command keeps what finished, status
// kInterrupted) and prints at once "COMMAND: stopping (Ctrl-C)WHAT; Ctrl-C
// again to quit now"; a second Ctrl-C exits kInterrupted at once.
const std::atomic<bool>* stop_on_interrupt(const std::string& command, const std::string& what);

// Help in the layout of every `vines` command: the usage line made of the
// command's arguments, its summary, one line per option (groups under their
// name), its notes. Set on the app before the commands.
void use_vines_help(CLI::App& vines);
// The message and status of a parse error: help asked for (stdout, 0), or a
// usage error with the command's help (stderr, 2).
int report_parse_error(const CLI::App& vines, const CLI::ParseError& e);

// The commands (sim_host/cli/<command>.cpp).
void add_run(CLI::App& vines);
void add_sweep(CLI::App& vines);
void add_design(CLI::App& vines);
void add_bench(CLI::App& vines);
void add_reference(CLI::App& vines);
void add_stress(CLI::App& vines);
void add_hil(CLI::App& vines);
void add_image(CLI::App& vines);
void add_node(CLI::App& vines);
void add_view(CLI::App& vines);
void add_help(CLI::App& vines);  // `vines help [COMMAND]` (help.cpp)

}  // namespace vines::cli
