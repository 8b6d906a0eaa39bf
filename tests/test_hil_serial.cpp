// `vines hil --node serial:DEVICE[@BAUD]` against `vines node --listen
// serial:...`, the two ends of a pseudo-terminal pair (socat): the bytes take
// the path a lab's USB serial port gives them (termios, raw 8N1), so the run
// is the pipe run bit for bit and survives every fault kind the bench can
// inject on a line as there; a line too slow for the rate, a device that is
// not there, a node that never answers and a line that breaks mid-run are
// each named.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/link/child.hpp"
#include "hil_support.hpp"

namespace vines::host {
namespace {

bool exists(const std::string& path) {
  struct stat st{};
  return ::stat(path.c_str(), &st) == 0;
}

// A pseudo-terminal pair: the node's end and the bench's (socat, which
// tools/setup.sh installs).
struct Line {
  std::string node_end, bench_end;
  std::unique_ptr<ChildProcess> socat;
  explicit Line(const std::string& name) {
    node_end = testing::TempDir() + name + "_node";
    bench_end = testing::TempDir() + name + "_bench";
    std::remove(node_end.c_str());
    std::remove(bench_end.c_str());
    socat = std::make_unique<ChildProcess>(std::vector<std::string>{
        "socat", "pty,raw,echo=0,link=" + node_end, "pty,raw,echo=0,ignoreeof,link=" + bench_end});
    for (int i = 0; i < 100 && !(exists(node_end) && exists(bench_end)); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  bool up() const { return exists(node_end) && exists(bench_end); }
};

// `vines node --listen serial:END@4000000` (or its other spelling, `--serial
// END@4000000`), once it says it listens.
struct SerialListener {
  ChildProcess node;
  bool listening = false;
  explicit SerialListener(const Line& line, bool serial_option = false)
      : node({VINES_EXE, "node", serial_option ? "--serial" : "--listen",
              (serial_option ? "" : "serial:") + line.node_end + "@4000000"}) {
    std::vector<std::uint8_t> out;
    for (int i = 0; i < 100 && !listening; ++i) {
      node.read_some(&out, 0.1);
      listening = std::string(out.begin(), out.end()).find("vines node: listening on serial:") != std::string::npos;
    }
  }
};

std::string run_error(const Scene& s, const HilOptions& o) {
  try {
    run_hil(s, o);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(HilSerial, NodeOnASerialLineEqualsThePipeRunAndSurvivesEveryFault) {
  Line line("vines_serial_faults");
  ASSERT_TRUE(line.up()) << "socat made no pseudo-terminal pair (is socat installed? tools/setup.sh)";
  SerialListener l(line);
  ASSERT_TRUE(l.listening);
  HilOptions serial = base(3.0);
  serial.node = "serial:" + line.bench_end + "@4000000";
  const HilReport clean = run_hil(vines_scene(), serial);
  EXPECT_TRUE(clean.bit_exact);  // the offline run's outputs, bit for bit, as over the pipes
  EXPECT_EQ(clean.max_deviation_from_offline, 0.0);
  EXPECT_EQ(clean.steps, clean.samples);
  // Every kind but the power cut, which a bench cannot give a board over its
  // data lines (refused below); the node on the line serves run after run.
  const FaultKind kinds[] = {FaultKind::kDrop, FaultKind::kCorrupt, FaultKind::kDuplicate,
                             FaultKind::kReorder, FaultKind::kLate, FaultKind::kNonFinite, FaultKind::kStall};
  for (FaultKind k : kinds) expect_fault_as_over_pipes(serial, k);
  HilOptions cut = serial;
  cut.faults[static_cast<int>(FaultKind::kRestart)] = parse_fault_spec("--restart", "@700");
  EXPECT_NE(run_error(vines_scene(), cut).find("--restart: the bench cannot cut the power of a node on a serial line"),
            std::string::npos);
}

// Refused before a byte is sent: the El Centro VI NES scene at 1 kHz sends
// 47-byte samples and gets 270-byte telemetry back (10 stories), which
// 921600 baud (92,160 bytes/s) cannot carry; 3,000,000 baud (the default)
// can.
TEST(HilSerial, ALineTooSlowForTheRateIsRefusedWithBothFigures) {
  HilOptions o = base(1.0);
  o.node = "serial:/dev/null-no-such-line@921600";  // never opened: the check comes first
  const std::string e = run_error(vines_scene(), o);
  EXPECT_NE(e.find("the line carries 92,160 bytes/s each way"), std::string::npos) << e;
  EXPECT_NE(e.find("this run needs 270,000 bytes/s (47 bytes a sample to the node, 270 back, at 1,000 Hz)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("set @3000000 or more"), std::string::npos) << e;
  o.node = "serial:/dev/null-no-such-line";  // the default baud: now the device is looked for
  EXPECT_NE(run_error(vines_scene(), o).find("No such file or directory (is the board plugged in?"), std::string::npos);
  o.node = "serial:/dev/null@3000000";
  EXPECT_NE(run_error(vines_scene(), o).find("not a serial line"), std::string::npos);
}

TEST(HilSerial, ANodeThatIsNotThereOrALineThatBreaksIsNamed) {
  Line line("vines_serial_gone");
  ASSERT_TRUE(line.up());
  // Nothing on the far end: silence, named by the bench's timeout.
  HilOptions o = base(1.0);
  o.node = "serial:" + line.bench_end + "@4000000";
  o.timeout_s = 0.5;
  EXPECT_NE(run_error(vines_scene(), o).find("no answer within 0.5"), std::string::npos);
  // The line cut one second into a real-time run (the adapter pulled): the
  // bench stops naming it, and writes no CSV rather than part of one.
  Line line2("vines_serial_cut");
  ASSERT_TRUE(line2.up());
  SerialListener l(line2, true);
  ASSERT_TRUE(l.listening);
  o = base(3.0);
  o.node = "serial:" + line2.bench_end + "@4000000";
  o.realtime = true;
  o.csv = testing::TempDir() + "hil_serial_cut.csv";
  std::remove(o.csv.c_str());
  std::thread cutter([&line2] {
    std::this_thread::sleep_for(std::chrono::seconds(1));
    line2.socat->kill_now();
  });
  const std::string e = run_error(vines_scene(), o);
  cutter.join();
  EXPECT_NE(e.find("node " + o.node + ": the line ended"), std::string::npos) << e;
  EXPECT_FALSE(std::ifstream(o.csv).good());
}

}  // namespace
}  // namespace vines::host
