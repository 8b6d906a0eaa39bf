#include "sim_host/hil/link/tcp.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include "sim_host/hil/link/fd_io.hpp"

namespace vines::host {
namespace {

int port_of(const std::string& text, const std::string& digits, bool zero_ok) {
  const bool number = !digits.empty() && digits.size() <= 5 &&
                      digits.find_first_not_of("0123456789") == std::string::npos;
  const int port = number ? std::stoi(digits) : -1;
  if (port < (zero_ok ? 0 : 1) || port > 65535)
    throw std::runtime_error(text + ": the port must be a number from " + (zero_ok ? "0" : "1") + " to 65535");
  return port;
}

void set_nodelay(int fd) {
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

struct Addresses {
  addrinfo* list = nullptr;
  ~Addresses() {
    if (list) ::freeaddrinfo(list);
  }
};

void resolve(const TcpAddress& a, bool passive, Addresses* out) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = passive ? AI_PASSIVE : 0;
  const std::string port = std::to_string(a.port);
  const int r = ::getaddrinfo(a.host.c_str(), port.c_str(), &hints, &out->list);
  if (r != 0) throw std::runtime_error((passive ? "--listen tcp:" : "--node tcp:") + to_string(a) + ": " + ::gai_strerror(r));
}

}  // namespace

TcpAddress parse_tcp_address(const std::string& text, const std::string& default_host, bool zero_ok) {
  if (!is_tcp(text)) throw std::runtime_error(text + ": not a TCP address (tcp:HOST:PORT)");
  const std::string rest = text.substr(4);
  TcpAddress a;
  if (!rest.empty() && rest[0] == '[') {
    const std::size_t close = rest.find(']');
    if (close == std::string::npos || close + 1 >= rest.size() || rest[close + 1] != ':')
      throw std::runtime_error(text + ": an IPv6 address is written tcp:[ADDRESS]:PORT");
    a.host = rest.substr(1, close - 1);
    a.port = port_of(text, rest.substr(close + 2), zero_ok);
  } else {
    const std::size_t colon = rest.rfind(':');
    if (colon == std::string::npos) {
      if (default_host.empty()) throw std::runtime_error(text + ": expected tcp:HOST:PORT");
      a.host = default_host;
      a.port = port_of(text, rest, zero_ok);
    } else {
      a.host = rest.substr(0, colon);
      if (a.host.find(':') != std::string::npos)
        throw std::runtime_error(text + ": an IPv6 address is written tcp:[ADDRESS]:PORT");
      a.port = port_of(text, rest.substr(colon + 1), zero_ok);
    }
  }
  if (a.host.empty()) throw std::runtime_error(text + ": no host before the port");
  return a;
}

std::string to_string(const TcpAddress& a) {
  const bool v6 = a.host.find(':') != std::string::npos;
  return (v6 ? "[" + a.host + "]" : a.host) + ":" + std::to_string(a.port);
}

TcpNode::TcpNode(const TcpAddress& a, double timeout_s) : name_(to_string(a)) {
  ::signal(SIGPIPE, SIG_IGN);  // a node gone shows as EPIPE, not a signal
  Addresses ad;
  resolve(a, false, &ad);
  std::string why = "no address";
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (addrinfo* p = ad.list; p && fd_ < 0; p = p->ai_next) {
    const int fd = ::socket(p->ai_family, p->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, p->ai_protocol);
    if (fd < 0) {
      why = std::strerror(errno);
      continue;
    }
    int err = ::connect(fd, p->ai_addr, p->ai_addrlen) == 0 ? 0 : errno;
    if (err == EINPROGRESS) {
      const double left = std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
      pollfd pf{fd, POLLOUT, 0};
      if (::poll(&pf, 1, poll_ms(left)) <= 0) {
        err = ETIMEDOUT;
      } else {
        socklen_t len = sizeof err;
        ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
      }
    }
    if (err == 0) {
      fd_ = fd;
      break;
    }
    ::close(fd);
    why = err == ECONNREFUSED ? "nothing listens there (connection refused; is `vines node --listen` running?)"
          : err == ETIMEDOUT ? "no answer within " + std::to_string(timeout_s) + " s (--timeout)"
                             : std::strerror(err);
  }
  if (fd_ < 0) throw std::runtime_error("--node tcp:" + name_ + ": " + why);
  set_nodelay(fd_);
}

TcpNode::~TcpNode() {
  if (fd_ >= 0) ::close(fd_);
}

void TcpNode::write_all(const std::uint8_t* p, std::size_t n, double timeout_s) {
  write_all_fd(fd_, p, n, timeout_s);
}

bool TcpNode::read_some(std::vector<std::uint8_t>* out, double timeout_s) { return read_some_fd(&fd_, out, timeout_s); }

int TcpNode::finish(double timeout_s) {
  if (fd_ < 0) return 0;
  ::shutdown(fd_, SHUT_WR);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::vector<std::uint8_t> rest;
  while (read_some_fd(&fd_, &rest, 0.05))
    if (std::chrono::steady_clock::now() > end) {
      kill_now();
      return 1;
    }
  return 0;
}

void TcpNode::kill_now() {
  if (fd_ < 0) return;
  const linger hard{1, 0};  // a reset, not an orderly close: the node sees the link cut
  ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &hard, sizeof hard);
  ::close(fd_);
  fd_ = -1;
}

int listen_tcp(const TcpAddress& a, int* port) {
  Addresses ad;
  resolve(a, true, &ad);
  std::string why = "no address";
  for (addrinfo* p = ad.list; p; p = p->ai_next) {
    const int fd = ::socket(p->ai_family, p->ai_socktype | SOCK_CLOEXEC, p->ai_protocol);
    if (fd < 0) {
      why = std::strerror(errno);
      continue;
    }
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd, p->ai_addr, p->ai_addrlen) != 0 || ::listen(fd, 1) != 0) {
      why = std::strerror(errno);
      ::close(fd);
      continue;
    }
    sockaddr_storage got{};
    socklen_t len = sizeof got;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&got), &len);
    *port = ntohs(got.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&got)->sin6_port
                                            : reinterpret_cast<sockaddr_in*>(&got)->sin_port);
    return fd;
  }
  throw std::runtime_error("--listen tcp:" + to_string(a) + ": cannot listen there: " + why);
}

int accept_bench(int listener) {
  for (;;) {
    const int fd = ::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd >= 0) {
      set_nodelay(fd);
      return fd;
    }
    if (errno != EINTR && errno != ECONNABORTED) return -1;
  }
}

}  // namespace vines::host
