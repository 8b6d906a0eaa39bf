// The bench's byte path to one node: a child process over pipes
// (child.hpp: `vines node`, a board in QEMU), a node listening on TCP
// (tcp.hpp: `vines node --listen`, another machine beside the table) or one
// on a serial line (serial.hpp: a board on a USB serial port). The link
// protocol on top is the same (node_link.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vines::host {

class NodeTransport {
 public:
  virtual ~NodeTransport() = default;
  // Writes everything or throws after timeout_s (node stuck or gone).
  virtual void write_all(const std::uint8_t* p, std::size_t n, double timeout_s) = 0;
  // Appends what the node sent within timeout_s (0: do not wait) to out;
  // false once its side is closed.
  virtual bool read_some(std::vector<std::uint8_t>* out, double timeout_s) = 0;
  // Ends the link and waits up to timeout_s for the node to end its side:
  // its exit status (a process; 128 + signal if killed), or 0 when a TCP
  // node closed the connection in time (1 if not), or a serial line drained.
  virtual int finish(double timeout_s) = 0;
  // Cuts the node off now (a power cut): a process killed, a connection reset.
  virtual void kill_now() = 0;
  // The node's process on this machine (a child), or -1 (TCP, a serial line).
  virtual int process() const { return -1; }
};

}  // namespace vines::host
