// The link over TCP: the bench's end (TcpNode, a transport to a node that
// `vines node --listen` runs on this machine or on one beside the table) and
// the node's (listen_tcp, accept_bench). One bench at a time; the bytes are
// the link protocol's, as over pipes (docs/link_protocol.md).
#pragma once

#include <string>

#include "sim_host/hil/link/transport.hpp"

namespace vines::host {

struct TcpAddress {
  std::string host;  // a name, an IPv4 address, or an IPv6 one (without brackets)
  int port = 0;
};

// Whether a --node or --listen text names a TCP address ("tcp:...").
inline bool is_tcp(const std::string& text) { return text.rfind("tcp:", 0) == 0; }

// "tcp:HOST:PORT" ("tcp:[IPv6]:PORT"; "tcp:PORT" with default_host when it is
// not empty). Throws std::runtime_error naming the text and what is wrong.
// Port 0 (any free port) only where zero_ok (a node listening).
TcpAddress parse_tcp_address(const std::string& text, const std::string& default_host, bool zero_ok);

// "HOST:PORT", "[IPv6]:PORT".
std::string to_string(const TcpAddress& a);

class TcpNode : public NodeTransport {
 public:
  // Connects within timeout_s, or throws naming the address: nothing
  // listening there, no answer, a name that does not resolve.
  TcpNode(const TcpAddress& a, double timeout_s);
  ~TcpNode() override;
  TcpNode(const TcpNode&) = delete;
  TcpNode& operator=(const TcpNode&) = delete;

  void write_all(const std::uint8_t* p, std::size_t n, double timeout_s) override;
  bool read_some(std::vector<std::uint8_t>* out, double timeout_s) override;
  int finish(double timeout_s) override;
  void kill_now() override;

 private:
  int fd_ = -1;
  std::string name_;
};

// A listening socket on a (port 0: a free one, written to *port), or throws
// naming the address (in use, not this machine's, ...).
int listen_tcp(const TcpAddress& a, int* port);

// The next bench's connection on listener (waits), its latency tuned
// (TCP_NODELAY); -1 with errno on failure.
int accept_bench(int listener);

}  // namespace vines::host
