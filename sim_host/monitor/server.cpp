#include "sim_host/monitor/server.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include <httplib.h>

#include "sim_host/monitor/page_assets.hpp"

namespace vines::host::monitor {

Address parse_address(const std::string& option, const std::string& value) {
  Address a;
  std::string port = value;
  if (!value.empty() && value[0] == '[') {  // [IPv6]:PORT
    const std::size_t close = value.find(']');
    if (close == std::string::npos || close + 1 >= value.size() || value[close + 1] != ':' || close == 1)
      throw std::invalid_argument(option + " " + value + ": expected [IPV6]:PORT, e.g. [::1]:8080");
    a.host = value.substr(1, close - 1);
    port = value.substr(close + 2);
  } else if (value.find(':') != value.rfind(':')) {
    throw std::invalid_argument(option + " " + value + ": an IPv6 address goes in brackets, [ADDRESS]:PORT, e.g. [::1]:8080");
  } else if (const std::size_t colon = value.rfind(':'); colon != std::string::npos) {
    a.host = value.substr(0, colon);
    port = value.substr(colon + 1);
    if (a.host.empty()) throw std::invalid_argument(option + " " + value + ": no host before ':' (HOST:PORT or PORT)");
  }
  // A port: digits only, 0 to 65535.
  const bool digits = !port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos;
  if (!digits || std::stol(port) > 65535)
    throw std::invalid_argument(option + " " + value + ": '" + port +
                                "' is not a port (0 to 65535; 0: any free one); expected [HOST:]PORT");
  a.port = static_cast<int>(std::stol(port));
  return a;
}

struct PageServer::Impl {
  explicit Impl(Hub& h) : hub(h) {}
  Hub& hub;
  httplib::Server srv;
  std::thread thread;
};

namespace {

// The event stream of one client: the hub's events from its cursor, until
// the hub's end, the client falls out of the history, or a write blocks past
// the write timeout (the client stopped reading): then it is dropped.
void serve_events(Hub& hub, httplib::Response& res) {
  const std::optional<long long> joined = hub.join();
  if (!joined) {
    res.status = 503;
    res.set_content("too many clients of this page\n", "text/plain");
    return;
  }
  auto cursor = std::make_shared<long long>(*joined);
  res.set_header("Cache-Control", "no-store");
  res.set_chunked_content_provider(
      "text/event-stream",
      [&hub, cursor](std::size_t, httplib::DataSink& sink) {
        std::vector<Event> events;
        switch (hub.next(cursor.get(), &events, std::chrono::milliseconds(250))) {
          case Hub::Next::kIdle: return true;
          case Hub::Next::kEnd: sink.done(); return true;
          case Hub::Next::kBehind: hub.count_dropped(); return false;
          case Hub::Next::kEvents: break;
        }
        for (const Event& e : events)
          if (!sink.write(e->data(), e->size())) {
            hub.count_dropped();
            return false;
          }
        return true;
      },
      [&hub](bool) { hub.leave(); });
}

}  // namespace

PageServer::PageServer(Hub& hub, const Address& at) : impl_(std::make_unique<Impl>(hub)), host_(at.host) {
  httplib::Server& srv = impl_->srv;
  // Read-only: GET (and HEAD) only; to the Host names it is bound to (a page
  // of another site, through DNS rebinding, cannot read it); one byte range
  // at most (a request of many would build a response many times the file).
  srv.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    auto refuse = [&res](int status, const std::string& why) {
      res.status = status;
      res.set_content(why + "\n", "text/plain");
      return httplib::Server::HandlerResponse::Handled;
    };
    // First, and with no body: cpp-httplib would cut any body into the
    // request's ranges.
    if (req.get_header_value("Range").find(',') != std::string::npos) {
      res.status = 416;
      res.set_header("X-Refused", "one byte range at most");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!host_allowed(req.get_header_value("Host")))
      return refuse(421, "this page answers to Host " + authority() + " only");
    if (req.method != "GET" && req.method != "HEAD") {
      res.set_header("Allow", "GET, HEAD");
      return refuse(405, "this page is read-only");
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  for (const PageFile& f : page_files()) {
    srv.Get(std::string(f.path), [f](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      res.set_content(f.body.data(), f.body.size(), std::string(f.type) + "; charset=utf-8");
    });
  }
  srv.Get("/events", [&hub](const httplib::Request&, httplib::Response& res) { serve_events(hub, res); });
  // A client that stops reading blocks its own thread for at most this long,
  // one that sends nothing too; one request a connection; threads for the
  // hub's clients (each holds one while it reads the events) and as many
  // more, with eight to spare.
  srv.set_write_timeout(1, 0);
  srv.set_read_timeout(5, 0);
  srv.set_keep_alive_max_count(1);
  const std::size_t threads = 2 * static_cast<std::size_t>(hub.limits().max_clients) + 8;
  srv.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  // SO_REUSEADDR only: httplib's default, SO_REUSEPORT, would let a second
  // program listen on a port in use (and share its clients).
  srv.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  errno = 0;
  port_ = at.port == 0 ? impl_->srv.bind_to_any_port(at.host) : (srv.bind_to_port(at.host, at.port) ? at.port : -1);
  if (port_ < 0) {
    const int e = errno;
    throw std::runtime_error("--serve " + at.host + ":" + std::to_string(at.port) +
                             ": cannot listen there (" + (e ? std::strerror(e) : "no such address") +
                             "; is the port in use, or the host not this machine's?)");
  }
  impl_->thread = std::thread([this] { impl_->srv.listen_after_bind(); });
  if (!loopback())
    std::fprintf(stderr,
                 "--serve %s: the page is open to every machine that can reach this one on port %d (read-only, no "
                 "password); --serve %d keeps it on this machine\n",
                 authority().c_str(), port_, port_);
}

bool PageServer::loopback() const { return host_ == "127.0.0.1" || host_ == "localhost" || host_ == "::1"; }

std::string PageServer::authority() const {
  return (host_.find(':') != std::string::npos ? "[" + host_ + "]" : host_) + ":" + std::to_string(port_);
}

// The Host header a browser sends for this server's URL: the bound name and
// port, or for a loopback server any of its names; any for one bound to
// every interface (0.0.0.0, ::: its names are not known; it warned).
bool PageServer::host_allowed(const std::string& host) const {
  if (host_ == "0.0.0.0" || host_ == "::") return true;
  const std::string port = ":" + std::to_string(port_);
  if (host == authority()) return true;
  if (!loopback()) return false;
  for (const char* name : {"127.0.0.1", "localhost", "[::1]"})
    if (host == name + port) return true;
  return false;
}

PageServer::~PageServer() { stop(std::chrono::milliseconds(0)); }

std::string PageServer::url() const { return "http://" + authority() + "/"; }

void PageServer::stop(std::chrono::milliseconds linger, bool hold) {
  if (!impl_->thread.joinable()) return;
  if (hold) impl_->hub.wait_until_read(linger);
  else impl_->hub.wait_until_no_clients(linger);
  // A server stopped before it runs would run on: wait for it to run first.
  for (int i = 0; i < 2000 && !impl_->srv.is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  impl_->srv.stop();
  impl_->thread.join();
}

}  // namespace vines::host::monitor
