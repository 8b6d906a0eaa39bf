// The link over a serial line (raw 8N1 through termios): the bench's end
// (SerialNode, `vines hil --node serial:DEVICE[@BAUD]`) and the node's
// (`vines node --listen serial:DEVICE[@BAUD]`, open_serial). The bytes are
// the link protocol's, as over pipes and TCP (docs/link_protocol.md); before
// a run the bench checks the line can carry its frames at the sensor rate.
#pragma once

#include <cstddef>
#include <string>

#include "sim_host/hil/link/transport.hpp"

namespace vines::host {

// The board images' UART (hal/mcu/stm32f405_board.hpp): what a 10-story node
// at 1 kHz needs, and what FTDI and CP2102N bridges reach.
inline constexpr long kDefaultBaud = 3000000;

struct SerialAddress {
  std::string device;  // /dev/ttyUSB0, /dev/ttyACM0, a pty
  long baud = kDefaultBaud;
};

// Whether a --node or --listen text names a serial line ("serial:...").
inline bool is_serial(const std::string& text) { return text.rfind("serial:", 0) == 0; }

// "serial:DEVICE[@BAUD]"; throws std::runtime_error naming the text and what
// is wrong (no device, a baud the line discipline has no speed for).
SerialAddress parse_serial_address(const std::string& text);

// "DEVICE@BAUD".
std::string to_string(const SerialAddress& a);

// The line open, raw 8N1 at its baud, no flow control, non-blocking, held
// exclusively (one bench, one node), stale bytes flushed; or throws naming
// the device and why (missing, no permission, in use, not a terminal).
int open_serial(const SerialAddress& a, const std::string& option);

// A run's bytes against the line: up_bytes the bench sends a sample, down_bytes
// the node answers (frames whole: COBS, CRC and delimiter), rate_hz samples a
// second; 8N1 moves baud / 10 bytes a second each way. Throws with both
// figures when the line cannot carry them.
void check_line_rate(const SerialAddress& a, double rate_hz, std::size_t up_bytes, std::size_t down_bytes);

class SerialNode : public NodeTransport {
 public:
  explicit SerialNode(const SerialAddress& a);
  ~SerialNode() override;
  SerialNode(const SerialNode&) = delete;
  SerialNode& operator=(const SerialNode&) = delete;

  void write_all(const std::uint8_t* p, std::size_t n, double timeout_s) override;
  bool read_some(std::vector<std::uint8_t>* out, double timeout_s) override;
  // The line stays up after STOP: waits for the bytes sent to leave (0).
  int finish(double timeout_s) override;
  // The bench cannot cut a board's power over its data lines: refused before
  // a run (bench.cpp), so this only closes the line.
  void kill_now() override;

 private:
  int fd_ = -1;
};

}  // namespace vines::host
