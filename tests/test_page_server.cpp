// The monitoring page's server (sim_host/monitor/server.hpp, libmicrohttpd),
// with cpp-httplib and raw sockets as its clients: it serves the page
// read-only, to the Host names it is bound to, one byte range at most;
// refuses a port in use; drops a client that stops reading while the bench
// publishes on undisturbed; and no client, slow, idle or half-sent, stalls
// the page or its stop (issue 53).
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <httplib.h>

#include "sim_host/monitor/hub.hpp"
#include "sim_host/monitor/server.hpp"

namespace vines::host::monitor {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

TEST(Server, ParsesHostAndPortAndNamesABadOne) {
  EXPECT_EQ(parse_address("--serve", "8080").host, "127.0.0.1");
  EXPECT_EQ(parse_address("--serve", "8080").port, 8080);
  const Address a = parse_address("--serve", "0.0.0.0:0");
  EXPECT_EQ(a.host, "0.0.0.0");
  EXPECT_EQ(a.port, 0);
  const Address v6 = parse_address("--serve", "[::1]:0");
  EXPECT_EQ(v6.host, "::1");
  EXPECT_EQ(v6.port, 0);
  for (const char* bad : {"", "abc", "70000", "-1", ":80", "localhost:", "8080x", "123456", "::1:0", "[::1]", "[]:80",
                          "[::1]80", "[::1"}) {
    try {
      parse_address("--serve", bad);
      ADD_FAILURE() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("--serve ") + bad), std::string::npos) << e.what();
    }
  }
}

// The page's files, GET only; /events gives the hub's events; a second
// server on the same port is refused, naming it.
TEST(Server, ServesThePageReadOnlyAndRefusesAPortInUse) {
  Hub hub;
  PageServer server(hub, Address{"127.0.0.1", 0});
  ASSERT_GT(server.port(), 0);
  httplib::Client cli("127.0.0.1", server.port());
  auto r = cli.Get("/");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_NE(r->body.find("/app.js"), std::string::npos);
  EXPECT_EQ(r->get_header_value("Content-Type"), "text/html; charset=utf-8");
  for (const char* f : {"/app.js", "/uPlot.iife.min.js", "/uPlot.min.css"}) {
    auto g = cli.Get(f);
    ASSERT_TRUE(g) << f;
    EXPECT_EQ(g->status, 200) << f;
    EXPECT_GT(g->body.size(), 1000u) << f;
  }
  EXPECT_EQ(cli.Get("/nothing")->status, 404);
  EXPECT_EQ(cli.Post("/events", "x", "text/plain")->status, 405);
  EXPECT_EQ(cli.Put("/", "x", "text/plain")->status, 405);
  EXPECT_EQ(cli.Delete("/")->status, 405);
  hub.set_header("event: meta\ndata: {}\n\n");
  hub.publish("event: frame\ndata: {\"k\":[0]}\n\n");
  hub.close();
  auto ev = cli.Get("/events");
  ASSERT_TRUE(ev);
  EXPECT_EQ(ev->get_header_value("Content-Type"), "text/event-stream");
  EXPECT_EQ(ev->body, "event: meta\ndata: {}\n\nevent: frame\ndata: {\"k\":[0]}\n\n");
  try {
    PageServer again(hub, Address{"127.0.0.1", server.port()});
    ADD_FAILURE() << "a port in use";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--serve 127.0.0.1:" + std::to_string(server.port())), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(PageServer(hub, Address{"203.0.113.7", 0}), std::runtime_error);  // not this machine's
}

// A raw request's status line (its first line), or "" if none came.
std::string raw_status(int port, const std::string& request) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return "";
  ::send(s, request.data(), request.size(), 0);
  std::string got;
  char buf[4096];
  for (ssize_t n; (n = ::recv(s, buf, sizeof buf, 0)) > 0;) got.append(buf, static_cast<std::size_t>(n));
  ::close(s);
  return got.substr(0, got.find("\r\n"));
}

// DNS rebinding: a page of another site that resolves its name to this
// machine sends its own Host; refused (421). The loopback names pass.
TEST(Server, AnswersOnlyToTheHostNamesItIsBoundTo) {
  Hub hub;
  PageServer server(hub, Address{"127.0.0.1", 0});
  const std::string port = std::to_string(server.port());
  for (const std::string host : {"127.0.0.1:" + port, "localhost:" + port, "[::1]:" + port})
    EXPECT_EQ(raw_status(server.port(), "GET / HTTP/1.1\r\nHost: " + host + "\r\n\r\n"), "HTTP/1.1 200 OK") << host;
  for (const std::string host : {"evil.example:" + port, std::string("127.0.0.1:1"), std::string("localhost"), std::string()})
    EXPECT_EQ(raw_status(server.port(), "GET / HTTP/1.1\r\nHost: " + host + "\r\n\r\n"),
              "HTTP/1.1 421 Misdirected Request")
        << host;
  EXPECT_EQ(raw_status(server.port(), "GET /events HTTP/1.1\r\nHost: evil.example\r\n\r\n"),
            "HTTP/1.1 421 Misdirected Request");
  EXPECT_EQ(server.authority(), "127.0.0.1:" + port);
}

// One byte range is served (206); many in one request are refused (416):
// 1,600 ranges "0-" of the index page built 2.9 MB from 1.8 KB.
TEST(Server, ServesOneRangeAndRefusesMany) {
  Hub hub;
  PageServer server(hub, Address{"127.0.0.1", 0});
  httplib::Client cli("127.0.0.1", server.port());
  auto one = cli.Get("/", {{"Range", "bytes=0-9"}});
  ASSERT_TRUE(one);
  EXPECT_EQ(one->status, 206);
  EXPECT_EQ(one->body.size(), 10u);
  std::string many = "bytes=0-";
  for (int i = 0; i < 1600; ++i) many += ",0-";
  auto amp = cli.Get("/", {{"Range", many}});
  ASSERT_TRUE(amp);
  EXPECT_EQ(amp->status, 416);
  EXPECT_EQ(amp->get_header_value("X-Refused"), "one byte range at most");
  EXPECT_EQ(amp->body.size(), 0u);
  EXPECT_EQ(raw_status(server.port(), "GET / HTTP/1.1\r\nHost: evil.example\r\nRange: " + many + "\r\n\r\n"),
            "HTTP/1.1 416 Range Not Satisfiable");
  // Ranges it cannot serve: past the file, numbers too long, two dashes, not bytes.
  for (const char* bad : {"bytes=999999-", "bytes=99999999999999999999999-", "bytes=0-1-2", "bytes=-0", "items=0-1"}) {
    auto r = cli.Get("/", {{"Range", bad}});
    ASSERT_TRUE(r) << bad;
    EXPECT_EQ(r->status, 416) << bad;
  }
  auto tail = cli.Get("/", {{"Range", "bytes=-5"}});
  ASSERT_TRUE(tail);
  EXPECT_EQ(tail->status, 206);
  EXPECT_EQ(tail->body.size(), 5u);
}

// Bound to every interface, it says so; bound to the IPv6 loopback, its URL
// has the address in brackets (skipped where the machine has no IPv6).
TEST(Server, WarnsBeyondLoopbackAndTakesIPv6) {
  Hub hub;
  testing::internal::CaptureStderr();
  { PageServer open(hub, Address{"0.0.0.0", 0}); }
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("open to every machine that can reach this one"), std::string::npos) << said;
  testing::internal::CaptureStderr();
  { PageServer local(hub, Address{"127.0.0.1", 0}); }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  std::unique_ptr<PageServer> v6;
  try {
    v6 = std::make_unique<PageServer>(hub, Address{"::1", 0});
  } catch (const std::runtime_error& e) {
    GTEST_SKIP() << "no IPv6 loopback here: " << e.what();
  }
  EXPECT_EQ(v6->url(), "http://[::1]:" + std::to_string(v6->port()) + "/");
  httplib::Client cli("::1", v6->port());
  auto r = cli.Get("/", {{"Host", "[::1]:" + std::to_string(v6->port())}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

// A client that asks for /events and never reads: its socket fills, its
// write times out and it is dropped, while the bench publishes 40 MB on
// without waiting and a reading client gets every event.
TEST(Server, DropsAClientThatStopsReadingWithoutStallingTheBench) {
  Hub hub;
  PageServer server(hub, Address{"127.0.0.1", 0});
  hub.set_header("event: meta\ndata: {}\n\n");
  // The client that stops reading: a raw socket, its receive buffer small.
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  const int small = 4096;
  ::setsockopt(s, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(server.port()));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::string get = "GET /events HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(server.port()) + "\r\n\r\n";
  ASSERT_EQ(::send(s, get.data(), get.size(), 0), static_cast<ssize_t>(get.size()));
  // The reading client.
  std::string body;
  std::thread reader([&] {
    httplib::Client cli("127.0.0.1", server.port());
    cli.set_read_timeout(30, 0);
    cli.Get("/events", [&](const char* p, std::size_t n) {
      body.append(p, n);
      return true;
    });
  });
  while (hub.clients() < 2) std::this_thread::sleep_for(1ms);
  const std::string event = "event: frame\ndata: " + std::string(10000, 'x') + "\n\n";
  double worst_publish_s = 0;
  const auto t0 = Clock::now();
  for (int i = 0; i < 4000; ++i) {
    const auto a = Clock::now();
    hub.publish(event);
    worst_publish_s = std::max(worst_publish_s, std::chrono::duration<double>(Clock::now() - a).count());
    if (i % 100 == 0) std::this_thread::sleep_for(5ms);  // a bench's pace: 2 MB/s
  }
  const double publish_s = std::chrono::duration<double>(Clock::now() - t0).count();
  for (int i = 0; i < 500 && hub.dropped() == 0; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(hub.dropped(), 1);
  hub.close();
  reader.join();
  ::close(s);
  // Its events whole, less the comments an idle stream sends (":", a blank line).
  std::string events;
  for (std::size_t at = 0; at < body.size();) {
    const std::size_t end = std::min(body.find('\n', at), body.size() - 1) + 1;
    if (body[at] != ':') events.append(body, at, end - at);
    at = end + (body[at] == ':' && end < body.size() && body[end] == '\n');  // a comment and its blank line
  }
  const std::string header = "event: meta\ndata: {}\n\n";
  ASSERT_EQ(events.size(), header.size() + 4000 * event.size());
  EXPECT_EQ(events.substr(0, header.size()), header);
  EXPECT_LT(worst_publish_s, 0.05) << "a publish waited";
  EXPECT_LT(publish_s, 10.0);
  server.stop(1000ms);
}

// A socket to the server, connected; -1 if not.
int connect_to(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(s);
    return -1;
  }
  return s;
}

// Slow clients (issue 53): one that sends a header byte every 0.4 s is cut
// 5 s after it came; sixteen that send nothing do not keep the page from
// another client; a 64 KB header is refused; and the stop closes a half-sent
// request at once rather than waiting for it.
TEST(Server, NoClientStallsThePageOrItsStop) {
  Hub hub;
  auto server = std::make_unique<PageServer>(hub, Address{"127.0.0.1", 0});
  const int port = server->port();
  const std::string start = "GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\nX-Slow: ";
  std::atomic<double> cut_after_s{-1};
  std::thread slow([&] {
    const int s = connect_to(port);
    ASSERT_GE(s, 0);
    ::send(s, start.data(), start.size(), MSG_NOSIGNAL);
    const auto t0 = Clock::now();
    for (int i = 0; i < 50; ++i) {
      std::this_thread::sleep_for(400ms);
      if (::send(s, "a", 1, MSG_NOSIGNAL) != 1) break;
      char c;
      if (::recv(s, &c, 1, MSG_DONTWAIT) == 0) break;  // closed by the server
    }
    cut_after_s = std::chrono::duration<double>(Clock::now() - t0).count();
    ::close(s);
  });
  std::vector<int> idle;
  for (int i = 0; i < 16; ++i) idle.push_back(connect_to(port));
  const auto t1 = Clock::now();
  EXPECT_EQ(raw_status(port, "GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n\r\n"),
            "HTTP/1.1 200 OK");
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t1).count(), 1.0);
  const std::string big = "GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\nX-Big: " +
                          std::string(64 * 1024, 'b') + "\r\n\r\n";
  EXPECT_NE(raw_status(port, big), "HTTP/1.1 200 OK");
  slow.join();
  EXPECT_GT(cut_after_s.load(), 4.0);
  EXPECT_LT(cut_after_s.load(), 8.0);
  for (int s : idle) ::close(s);
  // A request half sent when the page stops: the stop does not wait for it.
  const int half = connect_to(port);
  ::send(half, start.data(), start.size(), MSG_NOSIGNAL);
  std::this_thread::sleep_for(100ms);
  const auto t2 = Clock::now();
  server->stop(0ms);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t2).count(), 1.0);
  ::close(half);
}

// An event stream with nothing to read waits out of the server's one thread
// (suspended): it hears a comment each second and stays past its 2 s
// silence limit, it gets the next event at once, and a stop while it waits
// closes it at once (issue 53).
TEST(Server, AnIdleStreamStaysAndTheStopEndsIt) {
  Hub hub;
  auto server = std::make_unique<PageServer>(hub, Address{"127.0.0.1", 0});
  hub.set_header("event: meta\ndata: {}\n\n");
  const int s = connect_to(server->port());
  ASSERT_GE(s, 0);
  const std::string get = "GET /events HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(server->port()) + "\r\n\r\n";
  ASSERT_EQ(::send(s, get.data(), get.size(), MSG_NOSIGNAL), static_cast<ssize_t>(get.size()));
  std::string got;
  const auto read_for = [&](std::chrono::milliseconds d) {
    const auto end = Clock::now() + d;
    timeval tv{0, 50000};
    ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    char buf[4096];
    while (Clock::now() < end)
      if (const ssize_t n = ::recv(s, buf, sizeof buf, 0); n > 0) got.append(buf, static_cast<std::size_t>(n));
      else if (n == 0) break;
  };
  read_for(4500ms);
  EXPECT_NE(got.find("event: meta"), std::string::npos);
  std::size_t comments = 0;
  for (std::size_t at = got.find(":\n\n"); at != std::string::npos; at = got.find(":\n\n", at + 1)) ++comments;
  EXPECT_GE(comments, 2u) << got;
  EXPECT_EQ(hub.clients(), 1) << "the idle stream was dropped";
  const auto t0 = Clock::now();
  hub.publish("event: frame\ndata: 7\n\n");
  while (got.find("data: 7") == std::string::npos && Clock::now() - t0 < 2s) read_for(10ms);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 0.3);
  read_for(300ms);  // suspended again
  const auto t1 = Clock::now();
  server->stop(0ms);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t1).count(), 0.5);
  EXPECT_EQ(hub.clients(), 0);
  EXPECT_EQ(hub.dropped(), 1);  // it left before the run's end
  ::close(s);
}

}  // namespace
}  // namespace vines::host::monitor
