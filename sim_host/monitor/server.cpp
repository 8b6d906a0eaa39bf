#include "sim_host/monitor/server.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <microhttpd.h>

#include "sim_host/monitor/http_parse.hpp"
#include "sim_host/monitor/page_assets.hpp"

namespace vines::host::monitor {

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// The limits of every request (docs/hil.md, "The monitoring page"): its
// request line and headers within kHeaderTime and kHeaderBytes; silence (a
// client that sends nothing, or an event stream's that stops reading)
// within kIdleSeconds (kStreamIdleSeconds); the connections at once bounded
// (PageServer's constructor), all on the server's one thread.
constexpr auto kHeaderTime = 5s;
constexpr unsigned kIdleSeconds = 5;
constexpr unsigned kStreamIdleSeconds = 2;  // an event stream's client that stops reading
constexpr std::size_t kHeaderBytes = 16 * 1024;
constexpr auto kKeepAlive = 1s;  // an idle event stream sends a comment this often

}  // namespace

struct PageServer::Impl {
  explicit Impl(Hub& h) : hub(h) {}
  Hub& hub;
  MHD_Daemon* daemon = nullptr;

  // The connections whose request has not been read whole yet, with when
  // they came: the watchdog cuts those past kHeaderTime (a client that sends
  // a byte now and then never trips the idle timeout).
  struct Pending {
    int fd = -1;
    Clock::time_point since;
    bool cut = false;
  };
  std::mutex m;
  std::condition_variable cv;
  std::map<MHD_Connection*, Pending> pending;
  // The event streams waiting for the hub, out of the server's loop (its
  // one thread never waits): the waker resumes them when the hub changes,
  // and each second (a stream's keep-alive). None suspends once stopping.
  std::vector<MHD_Connection*> suspended;
  bool stopping = false;
  std::thread watchdog, waker;

  void watch() {
    std::unique_lock<std::mutex> lock(m);
    while (!stopping) {
      cv.wait_for(lock, 200ms);
      const auto now = Clock::now();
      for (auto& [c, p] : pending)
        if (!p.cut && now - p.since > kHeaderTime) ::shutdown(p.fd, SHUT_RDWR), p.cut = true;
    }
  }

  // Resumed outside the lock (MHD's own locks are taken by a resume, and its
  // thread holds them when it asks a stream for bytes): a suspended
  // connection stays until resumed, so none is freed meanwhile.
  void wake() {
    long long seen = 0;
    auto last = Clock::now();
    for (;;) {
      const long long changes = hub.wait_for_change(seen, 50ms);
      std::vector<MHD_Connection*> now;
      {
        std::lock_guard<std::mutex> lock(m);
        if (stopping && suspended.empty()) return;
        if (changes == seen && Clock::now() - last < kKeepAlive && !stopping) continue;
        now.swap(suspended);
      }
      seen = changes, last = Clock::now();
      for (MHD_Connection* c : now) MHD_resume_connection(c);
    }
  }
};

namespace {

// One client of /events: the hub's events from its cursor, copied into
// MHD's buffer as it asks for them; with none to give, the connection is
// suspended until the waker resumes it.
struct Stream {
  PageServer::Impl* impl = nullptr;
  MHD_Connection* connection = nullptr;
  long long cursor = 0;
  std::string out;  // bytes not yet given to MHD
  std::size_t at = 0;
  Clock::time_point last = Clock::now();
  bool ended = false;  // read to the end, or dropped already
};

ssize_t read_stream(void* cls, std::uint64_t, char* buf, std::size_t max) {
  auto* s = static_cast<Stream*>(cls);
  Hub& hub = s->impl->hub;
  if (s->at == s->out.size()) {
    s->out.clear(), s->at = 0;
    if (s->ended) return MHD_CONTENT_READER_END_OF_STREAM;
    std::vector<Event> events;
    // The hub asked under the waker's lock: a change after this answer wakes
    // the stream suspended below.
    std::unique_lock<std::mutex> lock(s->impl->m);
    switch (hub.next(&s->cursor, &events, 0ms)) {
      case Hub::Next::kEnd: s->ended = true; return MHD_CONTENT_READER_END_OF_STREAM;
      case Hub::Next::kBehind:
        hub.count_dropped(), s->ended = true;
        return MHD_CONTENT_READER_END_WITH_ERROR;
      case Hub::Next::kIdle:
        // A comment now and then, so that a client still reading is told
        // apart from one that stopped (whose socket fills).
        if (Clock::now() - s->last < kKeepAlive) {
          if (s->impl->stopping) return MHD_CONTENT_READER_END_WITH_ERROR;
          s->impl->suspended.push_back(s->connection);
          MHD_suspend_connection(s->connection);
          return 0;
        }
        s->out = ":\n\n";
        break;
      case Hub::Next::kEvents:
        for (const Event& e : events) s->out += *e;
        break;
    }
  }
  const std::size_t n = std::min(max, s->out.size() - s->at);
  std::memcpy(buf, s->out.data() + s->at, n);
  s->at += n;
  s->last = Clock::now();
  return static_cast<ssize_t>(n);
}

// The stream over: a client that left before the end (it stopped reading
// and timed out, or closed) counts as dropped.
void free_stream(void* cls) {
  auto* s = static_cast<Stream*>(cls);
  if (!s->ended) s->impl->hub.count_dropped();
  s->impl->hub.leave();
  delete s;
}

MHD_Result queue(MHD_Connection* c, unsigned status, MHD_Response* r) {
  MHD_add_response_header(r, MHD_HTTP_HEADER_CONNECTION, "close");  // one request a connection
  const MHD_Result q = MHD_queue_response(c, status, r);
  MHD_destroy_response(r);
  return q;
}

MHD_Response* text(const std::string& body) {
  MHD_Response* r = MHD_create_response_from_buffer(body.size(), const_cast<char*>(body.data()), MHD_RESPMEM_MUST_COPY);
  MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, "text/plain");
  return r;
}

const char* header(MHD_Connection* c, const char* name) {
  const char* v = MHD_lookup_connection_value(c, MHD_HEADER_KIND, name);
  return v ? v : "";
}

}  // namespace

PageServer::PageServer(Hub& hub, const Address& at) : impl_(std::make_unique<Impl>(hub)), host_(at.host) {
  // The listening socket, made here so that a refusal names its reason.
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string where = "--serve " + at.host + ":" + std::to_string(at.port);
  if (const int e = getaddrinfo(at.host.c_str(), std::to_string(at.port).c_str(), &hints, &found); e != 0)
    throw std::runtime_error(where + ": cannot listen there (" + gai_strerror(e) + ")");
  int fd = -1, err = 0;
  bool v6 = false;
  for (addrinfo* a = found; a && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      err = errno;
      continue;
    }
    // SO_REUSEADDR only: SO_REUSEPORT would let a second program listen on
    // a port in use (and share its clients).
    int yes = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0 || ::listen(fd, 64) != 0) {
      err = errno;
      ::close(fd);
      fd = -1;
      continue;
    }
    v6 = a->ai_family == AF_INET6;
  }
  freeaddrinfo(found);
  if (fd < 0)
    throw std::runtime_error(where + ": cannot listen there (" + std::strerror(err) +
                             "; is the port in use, or the host not this machine's?)");
  sockaddr_storage bound{};
  socklen_t len = sizeof bound;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &len);
  port_ = ntohs(v6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);

  // One thread for every connection (epoll; an event stream waiting for the
  // hub is suspended, not waited on), under the limits above; the
  // watchdog's list kept by the notifier.
  const auto notify = +[](void* cls, MHD_Connection* c, void**, MHD_ConnectionNotificationCode toe) {
    auto* impl = static_cast<Impl*>(cls);
    std::lock_guard<std::mutex> lock(impl->m);
    if (toe == MHD_CONNECTION_NOTIFY_STARTED) {
      const MHD_ConnectionInfo* i = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
      if (i) impl->pending[c] = Impl::Pending{i->connect_fd, Clock::now(), false};
    } else {
      impl->pending.erase(c);
    }
  };
  const auto answer = +[](void* cls, MHD_Connection* c, const char* url, const char* method, const char*, const char*,
                          std::size_t*, void** ctx) -> MHD_Result {
    auto* self = static_cast<PageServer*>(cls);
    if (*ctx != nullptr) return MHD_NO;  // a body: none is read
    // The request line and headers are in: no longer the watchdog's; the
    // answer at once (a request's body, if any, is not read: the connection
    // closes after the answer).
    *ctx = self;
    {
      std::lock_guard<std::mutex> lock(self->impl_->m);
      self->impl_->pending.erase(c);
    }
    return static_cast<MHD_Result>(self->answer(c, url, method));
  };
  const unsigned limit = 2 * static_cast<unsigned>(hub.limits().max_clients) + 56;  // 64 with 4 clients
  impl_->daemon = MHD_start_daemon(
      MHD_USE_EPOLL_INTERNAL_THREAD | MHD_ALLOW_SUSPEND_RESUME | (v6 ? MHD_USE_IPv6 : 0), 0,
      nullptr, nullptr, answer, this, MHD_OPTION_LISTEN_SOCKET, fd, MHD_OPTION_CONNECTION_TIMEOUT, kIdleSeconds,
      MHD_OPTION_CONNECTION_LIMIT, limit, MHD_OPTION_CONNECTION_MEMORY_LIMIT, kHeaderBytes,
      MHD_OPTION_NOTIFY_CONNECTION, notify, impl_.get(), MHD_OPTION_END);
  if (!impl_->daemon) {
    ::close(fd);
    throw std::runtime_error(where + ": the HTTP server (libmicrohttpd) did not start");
  }
  impl_->watchdog = std::thread([this] { impl_->watch(); });
  impl_->waker = std::thread([this] { impl_->wake(); });
  if (!loopback())
    std::fprintf(stderr,
                 "--serve %s: the page is open to every machine that can reach this one on port %d (read-only, no "
                 "password); --serve %d keeps it on this machine\n",
                 authority().c_str(), port_, port_);
}

// Read-only: GET (and HEAD) only; to the Host names it is bound to (a page
// of another site, through DNS rebinding, cannot read it); one byte range at
// most (a request of many would build a response many times the file).
int PageServer::answer(MHD_Connection* c, const char* url_c, const char* method_c) {
  const std::string url = url_c, method = method_c, range = header(c, MHD_HTTP_HEADER_RANGE);
  if (range.find(',') != std::string::npos) {  // first, and with no body
    MHD_Response* r = MHD_create_response_from_buffer(0, nullptr, MHD_RESPMEM_PERSISTENT);
    MHD_add_response_header(r, "X-Refused", "one byte range at most");
    return queue(c, MHD_HTTP_RANGE_NOT_SATISFIABLE, r);
  }
  if (!host_allowed(header(c, MHD_HTTP_HEADER_HOST)))
    return queue(c, MHD_HTTP_MISDIRECTED_REQUEST, text("this page answers to Host " + authority() + " only\n"));
  if (method != "GET" && method != "HEAD") {
    MHD_Response* r = text("this page is read-only\n");
    MHD_add_response_header(r, MHD_HTTP_HEADER_ALLOW, "GET, HEAD");
    return queue(c, MHD_HTTP_METHOD_NOT_ALLOWED, r);
  }
  if (url == "/events") {
    const std::optional<long long> joined = impl_->hub.join();
    if (!joined) return queue(c, MHD_HTTP_SERVICE_UNAVAILABLE, text("too many clients of this page\n"));
    auto* s = new Stream;
    s->impl = impl_.get(), s->connection = c, s->cursor = *joined;
    MHD_Response* r = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 64 * 1024, read_stream, s, free_stream);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, "text/event-stream");
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    // A client that stops reading is dropped after a short silence.
    MHD_set_connection_option(c, MHD_CONNECTION_OPTION_TIMEOUT, kStreamIdleSeconds);
    return queue(c, MHD_HTTP_OK, r);
  }
  for (const PageFile& f : page_files()) {
    if (url != f.path) continue;
    std::size_t from = 0, to = f.body.size() - 1;
    const bool part = !range.empty();
    if (part && !parse_byte_range(range, f.body.size(), &from, &to)) {
      MHD_Response* r = MHD_create_response_from_buffer(0, nullptr, MHD_RESPMEM_PERSISTENT);
      MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_RANGE, ("bytes */" + std::to_string(f.body.size())).c_str());
      return queue(c, MHD_HTTP_RANGE_NOT_SATISFIABLE, r);
    }
    MHD_Response* r = MHD_create_response_from_buffer(to - from + 1, const_cast<char*>(f.body.data() + from),
                                                      MHD_RESPMEM_PERSISTENT);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, (std::string(f.type) + "; charset=utf-8").c_str());
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(r, MHD_HTTP_HEADER_ACCEPT_RANGES, "bytes");
    if (part)
      MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_RANGE,
                              ("bytes " + std::to_string(from) + "-" + std::to_string(to) + "/" +
                               std::to_string(f.body.size()))
                                  .c_str());
    return queue(c, part ? MHD_HTTP_PARTIAL_CONTENT : MHD_HTTP_OK, r);
  }
  return queue(c, MHD_HTTP_NOT_FOUND, text("no such page\n"));
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

// The daemon's stop closes every connection, a client's half-sent request
// or unread stream included: it never waits on a client. No stream may be
// suspended then (MHD aborts): none suspends once stopping, the waker
// resumes the last ones and ends.
void PageServer::stop(std::chrono::milliseconds linger, bool hold) {
  if (!impl_->daemon) return;
  if (hold) impl_->hub.wait_until_read(linger);
  else impl_->hub.wait_until_no_clients(linger);
  {
    std::lock_guard<std::mutex> lock(impl_->m);
    impl_->stopping = true;
  }
  impl_->cv.notify_all();
  impl_->waker.join();
  impl_->watchdog.join();
  MHD_stop_daemon(impl_->daemon);
  impl_->daemon = nullptr;
}

}  // namespace vines::host::monitor
