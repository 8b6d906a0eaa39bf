// `vines hil --node tcp:HOST:PORT` against `vines node --listen`: the same
// link protocol over TCP, so the same run as over the pipes bit for bit,
// every fault kind survived as there (a power cut is the connection reset,
// and the node listening again is a cold node); a node that is not there,
// that vanishes mid-run or that speaks another protocol version is named.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/link/child.hpp"
#include "sim_host/hil/link/tcp.hpp"
#include "vines/bytes/crc32.hpp"
#include "vines/bytes/wire.hpp"
#include "vines/link/cobs.hpp"
#include "vines/link/frame.hpp"
#include "hil_support.hpp"

namespace vines::host {
namespace {

// `vines node --listen tcp:127.0.0.1:0` and the address it printed.
struct Listener {
  ChildProcess node{{VINES_EXE, "node", "--listen", "tcp:127.0.0.1:0"}};
  std::string address;
  Listener() {
    std::vector<std::uint8_t> out;
    const std::string says = "vines node: listening on ";
    for (int i = 0; i < 100 && address.empty(); ++i) {
      node.read_some(&out, 0.1);
      const std::string text(out.begin(), out.end());
      const std::size_t at = text.find(says), end = text.find('\n', at);
      if (at != std::string::npos && end != std::string::npos) address = text.substr(at + says.size(), end - at - says.size());
    }
  }
};

TEST(HilTcp, NodeOnTcpEqualsThePipeRunAndSurvivesEveryFault) {
  Listener l;
  ASSERT_EQ(l.address.rfind("tcp:127.0.0.1:", 0), 0u) << l.address;
  HilOptions tcp = base(3.0);
  tcp.node = l.address;
  const HilReport clean = run_hil(vines_scene(), tcp);
  EXPECT_TRUE(clean.bit_exact);  // the offline run's outputs, bit for bit, as over the pipes
  EXPECT_EQ(clean.max_deviation_from_offline, 0.0);
  EXPECT_EQ(clean.steps, clean.samples);
  EXPECT_EQ(clean.node_status.exit_status, 0);  // the node closed the link after STOP
  const FaultKind kinds[] = {FaultKind::kDrop, FaultKind::kCorrupt, FaultKind::kDuplicate, FaultKind::kReorder,
                             FaultKind::kLate, FaultKind::kNonFinite, FaultKind::kStall, FaultKind::kRestart};
  for (FaultKind k : kinds) expect_fault_as_over_pipes(tcp, k);
}

TEST(HilTcp, ANodeNotThereOrGoneIsNamed) {
  // Nothing listens on a port just freed.
  int port = 0;
  const int fd = listen_tcp(TcpAddress{"127.0.0.1", 0}, &port);
  ::close(fd);
  HilOptions o = base(1.0);
  o.node = "tcp:127.0.0.1:" + std::to_string(port);
  try {
    run_hil(vines_scene(), o);
    ADD_FAILURE() << "ran without a node";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nothing listens there"), std::string::npos) << e.what();
  }
  // A node killed one second into a real-time run: the bench stops, naming
  // it, and writes no CSV rather than part of one.
  Listener l;
  o = base(3.0);
  o.node = l.address;
  o.realtime = true;
  o.csv = testing::TempDir() + "hil_tcp_gone.csv";
  std::remove(o.csv.c_str());
  std::thread killer([&l] {
    std::this_thread::sleep_for(std::chrono::seconds(1));
    l.node.kill_now();
  });
  try {
    run_hil(vines_scene(), o);
    ADD_FAILURE() << "ran on without its node";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("node " + l.address + ": the connection ended"), std::string::npos)
        << e.what();
  }
  killer.join();
  EXPECT_FALSE(std::ifstream(o.csv).good());
}

// A node built from another checkout: its first frame, the status it sends
// unasked when a bench connects, whole and with a good CRC in protocol
// version 99, stops the bench saying so.
TEST(HilTcp, ANodeOfAnotherProtocolVersionIsNamed) {
  int port = 0;
  const int listener = listen_tcp(TcpAddress{"127.0.0.1", 0}, &port);
  std::thread fake([listener] {
    const int fd = accept_bench(listener);
    std::uint8_t raw[16], wire[32];
    link::Writer w(raw, sizeof raw);
    w.u8(99);
    w.u8(static_cast<std::uint8_t>(link::MsgType::kStatus));
    w.u16(0);
    w.u32(link::crc32(raw, w.size()));
    const std::size_t n = link::cobs_encode(raw, w.size(), wire, sizeof wire);
    wire[n] = 0;
    (void)::write(fd, wire, n + 1);  // its announcement (docs/link_protocol.md, "Session")
    std::this_thread::sleep_for(std::chrono::seconds(2));
    ::close(fd);
  });
  HilOptions o = base(1.0);
  o.node = "tcp:127.0.0.1:" + std::to_string(port);
  o.timeout_s = 5;
  try {
    run_hil(vines_scene(), o);
    ADD_FAILURE() << "ran against a node of another protocol";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("speaks link protocol version 99, this bench version " +
                                         std::to_string(link::kProtocolVersion)),
              std::string::npos)
        << e.what();
  }
  fake.join();
  ::close(listener);
}

}  // namespace
}  // namespace vines::host
