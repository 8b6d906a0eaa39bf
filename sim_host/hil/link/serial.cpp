#include "sim_host/hil/link/serial.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "sim_host/hil/link/fd_io.hpp"

namespace vines::host {
namespace {

struct Speed {
  long baud;
  speed_t code;
};
constexpr Speed kSpeeds[] = {{9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
                             {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
                             {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
                             {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000},
                             {3500000, B3500000}, {4000000, B4000000}};

const Speed* speed_of(long baud) {
  for (const Speed& s : kSpeeds)
    if (s.baud == baud) return &s;
  return nullptr;
}

std::string speed_list() {
  std::string l;
  for (const Speed& s : kSpeeds) l += (l.empty() ? "" : ", ") + std::to_string(s.baud);
  return l;
}

std::string thousands(double v) {
  std::string s = std::to_string(static_cast<long long>(std::llround(v)));
  for (int i = static_cast<int>(s.size()) - 3; i > 0; i -= 3) s.insert(static_cast<std::size_t>(i), ",");
  return s;
}

}  // namespace

SerialAddress parse_serial_address(const std::string& text) {
  if (!is_serial(text)) throw std::runtime_error(text + ": not a serial line (serial:DEVICE[@BAUD])");
  SerialAddress a;
  std::string rest = text.substr(7);
  const std::size_t at = rest.rfind('@');
  if (at != std::string::npos) {
    const std::string digits = rest.substr(at + 1);
    const bool number = !digits.empty() && digits.size() <= 8 && digits.find_first_not_of("0123456789") == std::string::npos;
    if (!number || !speed_of(std::stol(digits)))
      throw std::runtime_error(text + ": the baud must be one of " + speed_list());
    a.baud = std::stol(digits);
    rest = rest.substr(0, at);
  }
  if (rest.empty()) throw std::runtime_error(text + ": no device (serial:/dev/ttyUSB0, serial:/dev/ttyACM0@115200)");
  a.device = rest;
  return a;
}

std::string to_string(const SerialAddress& a) { return a.device + "@" + std::to_string(a.baud); }

int open_serial(const SerialAddress& a, const std::string& option) {
  const std::string name = option + " serial:" + to_string(a) + ": ";
  const int fd = ::open(a.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    throw std::runtime_error(name + std::strerror(e) +
                             (e == ENOENT ? " (is the board plugged in? `ls /dev/serial/by-id`)"
                              : e == EACCES ? " (join the group that owns it, usually dialout)"
                                            : ""));
  }
  auto fail = [&](const std::string& why) {
    ::close(fd);
    throw std::runtime_error(name + why);
  };
  termios t{};
  if (::tcgetattr(fd, &t) != 0) fail("not a serial line (" + std::string(std::strerror(errno)) + ")");
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) fail("in use by another program (it holds the line's lock)");
  ::cfmakeraw(&t);
  t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS | CSIZE);
  t.c_cflag |= CS8 | CLOCAL | CREAD;
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  const speed_t code = speed_of(a.baud)->code;
  if (::cfsetispeed(&t, code) != 0 || ::cfsetospeed(&t, code) != 0 || ::tcsetattr(fd, TCSANOW, &t) != 0)
    fail("cannot set raw 8N1 at " + std::to_string(a.baud) + " baud (" + std::strerror(errno) + ")");
  ::tcflush(fd, TCIOFLUSH);  // what an earlier program left on the line
  return fd;
}

void check_line_rate(const SerialAddress& a, double rate_hz, std::size_t up_bytes, std::size_t down_bytes) {
  const double carries = static_cast<double>(a.baud) / 10.0;  // 8N1: start, 8 data, stop bits
  const double need = rate_hz * static_cast<double>(up_bytes > down_bytes ? up_bytes : down_bytes);
  if (need <= carries) return;
  const long* fit = nullptr;
  for (const Speed& s : kSpeeds)
    if (s.baud / 10.0 >= need) {
      fit = &s.baud;
      break;
    }
  throw std::runtime_error(
      "--node serial:" + to_string(a) + ": the line carries " + thousands(carries) + " bytes/s each way (8N1: " +
      std::to_string(a.baud) + " baud / 10 bits a byte); this run needs " + thousands(need) + " bytes/s (" +
      std::to_string(up_bytes) + " bytes a sample to the node, " + std::to_string(down_bytes) + " back, at " +
      thousands(rate_hz) + " Hz): " +
      (fit ? "set @" + std::to_string(*fit) + " or more, or a lower sensor rate"
           : "no baud carries it: lower the sensor rate or use a TCP node"));
}

SerialNode::SerialNode(const SerialAddress& a) : fd_(open_serial(a, "--node")) {}

SerialNode::~SerialNode() {
  if (fd_ >= 0) ::close(fd_);
}

void SerialNode::write_all(const std::uint8_t* p, std::size_t n, double timeout_s) {
  write_all_fd(fd_, p, n, timeout_s);
}

bool SerialNode::read_some(std::vector<std::uint8_t>* out, double timeout_s) {
  return read_some_fd(&fd_, out, timeout_s, true);
}

int SerialNode::finish(double) {
  if (fd_ >= 0) ::tcdrain(fd_);
  return 0;
}

void SerialNode::kill_now() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace vines::host
