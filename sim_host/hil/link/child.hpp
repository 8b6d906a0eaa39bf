// A child process with pipes to its stdin and stdout (the host node of
// `vines hil`). Every wait has a timeout; the child is killed and reaped by
// the destructor at the latest.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "sim_host/hil/link/transport.hpp"

namespace vines::host {

class ChildProcess : public NodeTransport {
 public:
  // Starts argv[0] (a path, or a program on PATH) with argv (throws
  // std::runtime_error naming it on failure).
  explicit ChildProcess(const std::vector<std::string>& argv);
  ~ChildProcess() override;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Writes everything or throws after timeout_s (child stuck or gone).
  void write_all(const std::uint8_t* p, std::size_t n, double timeout_s) override;
  // Appends what the child wrote within timeout_s (0: do not wait) to out;
  // returns false once the child's stdout is closed.
  bool read_some(std::vector<std::uint8_t>* out, double timeout_s) override;
  // Closes its stdin and waits up to timeout_s for it to exit, then kills it.
  // Returns its exit status (128 + signal if killed).
  int finish(double timeout_s) override;
  // SIGKILL now (a firmware crash / power cut), and reap it.
  void kill_now() override;
  pid_t pid() const { return pid_; }
  int process() const override { return pid_; }

 private:
  pid_t pid_ = -1;
  int in_ = -1, out_ = -1;  // our ends: its stdin, its stdout
  int status_ = -1;
};

// This program's own path (to run `vines node`).
std::string self_exe();

}  // namespace vines::host
