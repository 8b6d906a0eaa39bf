// The monitoring page on the command line (sim_host/monitor/): --serve of
// `vines hil` and `vines view`, and the page served while a command runs.
// Without libmicrohttpd in the build, the page is refused with the reason.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "sim_host/hil/watch.hpp"

namespace vines::cli {

// Adds --serve ADDRESS ([HOST:]PORT) to a command, into *at ("" : not given); a value
// that is not [HOST:]PORT is a usage error naming it.
CLI::Option* add_serve(CLI::App& cmd, std::string* at, const std::string& help);

// The page of one command: its hub, then its server.
class ServedPage {
 public:
  // Throws std::runtime_error saying so when the build has no page.
  ServedPage();
  ~ServedPage();
  // Listens at AT ([HOST:]PORT) and prints "COMMAND: the page is at URL" on
  // stderr; throws std::runtime_error naming the address if it cannot.
  void listen(const std::string& command, const std::string& at);
  // vines hil: the watch to give run_hil.
  host::HilWatch* watch();
  // vines view: the run's --csv (a file, or a folder with one) into the page.
  void load(const std::string& path);
  // Gives the clients up to `linger` to read the last events, then stops;
  // with `hold`, up to `linger` for a client to have read the whole run.
  void stop(std::chrono::milliseconds linger, bool hold = false);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vines::cli
