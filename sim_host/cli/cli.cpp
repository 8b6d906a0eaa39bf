// Shared pieces of the commands: registration, number lists and ranges, Ctrl-C.
#include "sim_host/cli/cli.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <utility>

namespace vines::cli {

CLI::App* add_command(CLI::App& vines, const std::string& name, const std::string& summary, const std::string& notes,
                      std::function<int()> run) {
  CLI::App* cmd = vines.add_subcommand(name, summary);
  cmd->footer(notes);
  cmd->callback([run = std::move(run)] {
    const int status = run();
    if (status != kOk) throw CLI::RuntimeError(status);  // main returns it
  });
  return cmd;
}

CLI::Option* add_accept_degraded(CLI::App& cmd, bool* accept) {
  return cmd.add_flag("--accept-degraded", *accept,
                      "exit 0 when results are degraded (they are still marked so; default: exit status 3)");
}

namespace {

// "a,b,c" -> *xs: every item a finite number > 0 (with whole: an integer from
// lo to hi, 0 too if lo is); else the reason, naming the list.
std::string parse_list(const std::string& text, bool whole, double lo, double hi, std::vector<double>* xs) {
  xs->clear();
  for (std::size_t start = 0;;) {
    const std::size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x) || (!whole && !(x > 0)))
      return std::string(whole ? "not a list of integers: " : "not a list of positive numbers: ") + text;
    if (whole && (x != std::floor(x) || x < lo || x > hi)) {
      char range[64];
      std::snprintf(range, sizeof range, "[%g, %g]", lo, hi);
      return "not a list of integers in " + std::string(range) + ": " + text;
    }
    xs->push_back(x);
    if (comma == std::string::npos) return "";
    start = comma + 1;
  }
}

CLI::Option* add_list(CLI::App& cmd, const std::string& name, bool whole, double lo, double hi,
                      std::function<void(const std::vector<double>&)> store, const std::string& help) {
  const auto check = [=](std::string& text) {
    std::vector<double> xs;
    return parse_list(text, whole, lo, hi, &xs);
  };
  const auto set = [=](const std::string& text) {
    std::vector<double> xs;
    parse_list(text, whole, lo, hi, &xs);  // checked above
    store(xs);
  };
  return cmd.add_option_function<std::string>(name, set, help)->type_name("LIST")->check(CLI::Validator(check, ""));
}

// A bound as a message shows it: whole numbers in full (1000000, not 1e+06).
std::string number_text(double x) {
  char s[32];
  std::snprintf(s, sizeof s, x == std::floor(x) && std::fabs(x) < 1e18 ? "%.0f" : "%g", x);
  return s;
}

// Ctrl-C: the flag, and the line the handler writes (set before the
// handler is installed; write(2) and _exit are async-signal-safe).
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the handler needs a lock-free flag");
char g_ack[512];
std::size_t g_ack_len = 0;

void on_interrupt(int) {
  if (g_stop.exchange(true)) _exit(kInterrupted);
  const ssize_t n = write(STDERR_FILENO, g_ack, g_ack_len);
  (void)n;  // nothing to do if stderr is gone
}

}  // namespace

CLI::Option* add_number_list(CLI::App& cmd, const std::string& name, std::vector<double>* out, const std::string& help) {
  return add_list(cmd, name, false, 0, 0, [out](const std::vector<double>& xs) { *out = xs; }, help);
}

CLI::Option* add_number_list(CLI::App& cmd, const std::string& name, std::vector<int>* out, int lo, int hi,
                             const std::string& help) {
  return add_list(
      cmd, name, true, lo, hi, [out](const std::vector<double>& xs) { out->assign(xs.begin(), xs.end()); }, help);
}

CLI::Validator number_in(double lo, double hi) {
  const std::string range = hi < 1e18 ? "from " + number_text(lo) + " to " + number_text(hi) : ">= " + number_text(lo);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        char* end = nullptr;
        const double x = std::strtod(text.c_str(), &end);
        if (!text.empty() && *end == '\0' && x >= lo && x <= hi) return "";
        return "not a number " + range + ": " + text;
      },
      "");
}

CLI::Validator positive_up_to(double hi) {
  const std::string range =
      hi < std::numeric_limits<double>::max() ? "in (0, " + number_text(hi) + "]" : "> 0";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        char* end = nullptr;
        const double x = std::strtod(text.c_str(), &end);
        if (!text.empty() && *end == '\0' && x > 0 && x <= hi) return "";
        return "not a number " + range + ": " + text;
      },
      "");
}

CLI::Validator non_empty_path() {
  return CLI::Validator([](std::string& path) { return path.empty() ? "an empty path names no file or folder" : ""; },
                        "");
}

const std::atomic<bool>* stop_on_interrupt(const std::string& command, const std::string& what) {
  const std::string line = "\n" + command + ": stopping (Ctrl-C)" + what + "; Ctrl-C again to quit now\n";
  g_ack_len = std::min(line.size(), sizeof g_ack);
  std::memcpy(g_ack, line.data(), g_ack_len);
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  return &g_stop;
}

}  // namespace vines::cli
