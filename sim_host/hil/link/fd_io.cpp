#include "sim_host/hil/link/fd_io.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace vines::host {

int poll_ms(double s) { return s <= 0 ? 0 : static_cast<int>(std::min(s * 1e3 + 0.999, 1e9)); }

void write_all_fd(int fd, const std::uint8_t* p, std::size_t n, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (n > 0) {
    const ssize_t w = fd >= 0 ? ::write(fd, p, n) : -1;
    if (w > 0) {
      p += w;
      n -= static_cast<std::size_t>(w);
      continue;
    }
    if (fd < 0) throw std::runtime_error("node: the link is closed");
    if (w < 0 && errno != EAGAIN && errno != EINTR)
      throw std::runtime_error(std::string("node: cannot write to it: ") + std::strerror(errno));
    const double left = std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
    if (left <= 0) throw std::runtime_error("node: not reading its input (write timed out)");
    pollfd pf{fd, POLLOUT, 0};
    ::poll(&pf, 1, poll_ms(left));
  }
}

bool read_some_fd(int* fd, std::vector<std::uint8_t>* out, double timeout_s, bool terminal) {
  if (*fd < 0) return false;
  pollfd pf{*fd, POLLIN, 0};
  const double t = std::max(0.0, std::min(timeout_s, 1e6));
  timespec ts{static_cast<time_t>(t), static_cast<long>((t - std::floor(t)) * 1e9)};
  const int r = ::ppoll(&pf, 1, &ts, nullptr);
  if (r <= 0) return true;
  std::uint8_t buf[8192];
  for (;;) {
    const ssize_t n = ::read(*fd, buf, sizeof buf);
    if (n > 0) {
      out->insert(out->end(), buf, buf + n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return true;
    if (n == 0 && terminal && !(pf.revents & (POLLHUP | POLLERR))) return true;
    ::close(*fd);
    *fd = -1;
    return false;
  }
}

}  // namespace vines::host
