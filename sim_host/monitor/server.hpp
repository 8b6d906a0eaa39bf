// The page's HTTP server, on libmicrohttpd (one thread of its own for every
// connection, epoll): GET of the page's files and of /events, the hub's events as
// Server-Sent Events; any other method refused (405): nothing on the page can
// change the run. Every request is bounded: its headers in time and bytes, its
// silence, the connections at once; stopping closes every connection.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "sim_host/monitor/http_parse.hpp"
#include "sim_host/monitor/hub.hpp"

struct MHD_Connection;

namespace vines::host::monitor {

class PageServer {
 public:
  struct Impl;  // server.cpp's: the daemon, its watchdog and its streams' waker
  // Listens at once (the port known when this returns) and serves on its
  // own threads; throws std::runtime_error naming the address if it cannot.
  // Bound beyond loopback, it says so on stderr. One request a connection,
  // its request line and headers within 5 s and 16 KB, one byte range at
  // most (416 otherwise), Host one of the names it is bound to (421
  // otherwise).
  PageServer(Hub& hub, const Address& at);
  ~PageServer();  // stop(0)
  PageServer(const PageServer&) = delete;
  PageServer& operator=(const PageServer&) = delete;

  int port() const { return port_; }
  std::string url() const;
  std::string authority() const;  // HOST:PORT, an IPv6 host in brackets
  // Gives the clients up to `linger` to read the hub's last events (close it
  // first), then stops. With `hold`, waits up to `linger` for a client to
  // have read the whole run (one may not have come yet), then stops.
  void stop(std::chrono::milliseconds linger, bool hold = false);

 private:
  int answer(MHD_Connection* c, const char* url, const char* method);  // an MHD_Result
  bool loopback() const;
  bool host_allowed(const std::string& host) const;
  std::unique_ptr<Impl> impl_;
  std::string host_;
  int port_ = 0;
};

}  // namespace vines::host::monitor
