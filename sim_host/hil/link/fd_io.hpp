// Byte I/O on a non-blocking file descriptor (a pipe or a socket) with
// timeouts: what the transports to a node share (child.hpp, tcp.hpp, serial.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vines::host {

// Writes everything or throws std::runtime_error after timeout_s ("not
// reading its input") or on an error (its reason).
void write_all_fd(int fd, const std::uint8_t* p, std::size_t n, double timeout_s);

// Appends what arrives within timeout_s (0: do not wait) to out; at the end
// of input (or an error) closes *fd, sets it to -1 and returns false. A
// terminal in raw mode reads 0 bytes when none have come: with terminal, the
// end is its hang-up or an error (a board unplugged: EIO), not a 0.
bool read_some_fd(int* fd, std::vector<std::uint8_t>* out, double timeout_s, bool terminal = false);

// Milliseconds for poll(): s rounded up, 0 for s <= 0.
int poll_ms(double s);

}  // namespace vines::host
