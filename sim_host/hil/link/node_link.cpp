#include "sim_host/hil/link/node_link.hpp"

#include <algorithm>
#include <stdexcept>

#include "sim_host/hil/link/boards.hpp"
#include "sim_host/hil/link/child.hpp"
#include "sim_host/hil/link/serial.hpp"
#include "sim_host/hil/link/tcp.hpp"

namespace vines::host {

using link::Telemetry;

double seconds_since(HilClock::time_point t0) { return std::chrono::duration<double>(HilClock::now() - t0).count(); }

NodeLink::NodeLink(const HilOptions& opt, long long life, std::vector<link::Fault>* faults,
                   std::vector<long long>* fault_life)
    : opt_(opt), life_(life), faults_(faults), fault_life_(fault_life),
      name_(is_tcp(opt.node) || is_serial(opt.node) ? opt.node : argv(opt)[0]), link_(open(opt)) {}

std::unique_ptr<NodeTransport> NodeLink::open(const HilOptions& opt) {
  if (is_tcp(opt.node)) return std::make_unique<TcpNode>(parse_tcp_address(opt.node, "", false), opt.timeout_s);
  if (is_serial(opt.node)) return std::make_unique<SerialNode>(parse_serial_address(opt.node));
  return std::make_unique<ChildProcess>(argv(opt));
}

// A board image runs in QEMU; any other node is a program run as `PROGRAM node`.
std::vector<std::string> NodeLink::argv(const HilOptions& opt) {
  if (!opt.image.empty() && opt.node.rfind("qemu:", 0) == 0) return qemu_argv(*board_of(opt.node), opt.image);
  std::vector<std::string> a = {opt.node_command.empty() ? self_exe() : opt.node_command, "node"};
  if (opt.realtime) a.push_back("--realtime");
  if (opt.rt_priority > 0) a.insert(a.end(), {"--realtime-priority", std::to_string(opt.rt_priority)});
  if (opt.node_cpu() >= 0) a.insert(a.end(), {"--cpu", std::to_string(opt.node_cpu())});
  return a;
}

std::vector<std::uint8_t> NodeLink::encode_empty(link::MsgType type) {
  std::vector<std::uint8_t> w(link::kMaxWire);
  w.resize(link::encode_frame(type, seq_++, nullptr, 0, w.data(), w.size()));
  return w;
}

void NodeLink::send(const std::vector<std::uint8_t>& bytes) {
  try {
    link_->write_all(bytes.data(), bytes.size(), opt_.timeout_s);
  } catch (const std::runtime_error& e) {
    if (is_tcp(name_) || is_serial(name_))
      throw std::runtime_error("node " + name_ + ": the " + (is_tcp(name_) ? "connection" : "line") + " ended (" +
                               e.what() + ")");
    throw std::runtime_error(name_ + ": " + e.what());
  }
  delimiters_ += static_cast<std::uint32_t>(std::count(bytes.begin(), bytes.end(), 0));
}

void NodeLink::pump(double timeout_s) {
  const bool open = read(timeout_s);
  // A node ends after answering STOP; before that, an exit is a failure.
  if (!open && acked_ < delimiters_) {
    const std::string unanswered = " with " + std::to_string(delimiters_ - acked_) + " frames unanswered";
    throw gone(unanswered);
  }
}

// The node is gone: its connection or line ended, or its process exited.
std::runtime_error NodeLink::gone(const std::string& tail) {
  if (is_tcp(name_) || is_serial(name_))
    return std::runtime_error("node " + name_ + ": the " + (is_tcp(name_) ? "connection" : "line") + " ended" + tail);
  return std::runtime_error("node " + name_ + " exited (status " + std::to_string(link_->finish(1)) + ")" + tail);
}

void NodeLink::kill() {
  link_->kill_now();
  // What it sent before it died is still in the pipe: read until the pipe
  // ends, or 0.1 s without a byte (a program that left the pipe open).
  for (std::size_t n = 1; n > 0;) {
    if (!read(0.1)) break;
    n = buf_.size();
  }
}

bool NodeLink::read(double timeout_s) {
  buf_.clear();
  const bool open = link_->read_some(&buf_, timeout_s);
  const double now = seconds_since(t0_);
  for (std::uint8_t b : buf_) {
    const link::DecodeResult r = dec_.push(b);
    if (r == link::DecodeResult::kNone) continue;
    if (r == link::DecodeResult::kBadVersion)  // a whole frame, its CRC good: another protocol
      throw std::runtime_error("node " + name_ + " speaks link protocol version " +
                               std::to_string(dec_.frame().version) + ", this bench version " +
                               std::to_string(link::kProtocolVersion) + " (docs/link_protocol.md): build both from "
                               "the same checkout");
    if (r != link::DecodeResult::kFrame) {
      ++bad_frames_;
      continue;
    }
    const link::Frame& f = dec_.frame();
    if (f.type == link::MsgType::kTelemetry) {
      Telemetry t;
      if (!link::decode(f.payload, f.length, &t)) ++bad_frames_;
      else on_telemetry(t, now), acked_ = std::max(acked_, t.rx);
    } else if (f.type == link::MsgType::kFault) {
      link::Fault x;
      if (!link::decode(f.payload, f.length, &x)) ++bad_frames_;
      else faults_->push_back(x), fault_life_->push_back(life_), acked_ = std::max(acked_, x.rx);
    } else if (f.type == link::MsgType::kStatus) {
      if (!link::decode(f.payload, f.length, &status_)) {
        ++bad_frames_;
      } else {
        if (statuses_++ == 0) first_cold_start_ = status_.cold_start == 1 && status_.steps == 0;
        acked_ = std::max(acked_, status_.rx);
      }
    } else {
      ++bad_frames_;
    }
  }
  return open;
}

void NodeLink::await_announce() {
  if (is_serial(opt_.node)) return;
  const auto end = HilClock::now() + std::chrono::duration<double>(opt_.timeout_s);
  while (statuses_ == 0) {
    const double left = std::chrono::duration<double>(end - HilClock::now()).count();
    if (left <= 0)
      throw std::runtime_error("node " + name_ + ": no answer within " + std::to_string(opt_.timeout_s) +
                               " s: it did not say it listens (--timeout)");
    if (!read(std::min(left, 0.05)) && statuses_ == 0) throw gone(" before it said it listens");
  }
}

void NodeLink::wait_answered(std::uint32_t in_flight) {
  const auto end = HilClock::now() + std::chrono::duration<double>(opt_.timeout_s);
  while (acked_ + in_flight < delimiters_) {
    const double left = std::chrono::duration<double>(end - HilClock::now()).count();
    if (left <= 0)
      throw std::runtime_error("node " + name_ + ": no answer within " + std::to_string(opt_.timeout_s) + " s to frame " +
                               std::to_string(delimiters_) + " (--timeout)");
    pump(std::min(left, 0.05));
  }
}

namespace {

// Sends one part of the configuration in chunks.
void send_part(NodeLink& node, link::ConfigPart part, const std::uint8_t* bytes, std::size_t n) {
  const std::uint32_t crc = link::crc32(bytes, n);
  for (std::size_t off = 0; off < n; off += link::kChunk) {
    link::ConfigureChunk c{part, static_cast<std::uint32_t>(off), static_cast<std::uint32_t>(n), crc, bytes + off,
                           static_cast<std::uint16_t>(std::min(link::kChunk, n - off))};
    node.send(node.encode(link::MsgType::kConfigure, c));
  }
}

}  // namespace

void configure(NodeLink& node, const link::NodeConfig& cfg, const std::vector<std::uint8_t>& image) {
  node.await_announce();
  if (!image.empty()) {
    send_part(node, link::ConfigPart::kModelImage, image.data(), image.size());
    node.wait_answered();
    if (node.status().message[0] != '\0')
      throw std::runtime_error(std::string("node refused the model image: ") + node.status().message);
  }
  std::uint8_t blob[link::kMaxConfigBlob];
  const std::size_t n = link::encode(cfg, blob, sizeof blob);
  if (n == 0) throw std::runtime_error("configuration does not fit the link");
  send_part(node, link::ConfigPart::kSettings, blob, n);
  node.wait_answered();
  if (node.statuses() == 0)  // faults only: a serial node whose line outlived the last bench
    throw std::runtime_error("node " + node.name() + " answered the configuration with faults only: it is still in "
                             "another bench's run, and takes a new one after its --idle-timeout of silence (30 s "
                             "unless set)");
  if (node.status().state != link::NodeState::kConfigured)
    throw std::runtime_error(std::string("node refused the configuration: ") + node.status().message);
}

void start(NodeLink& node, long long k0, std::uint64_t t_ns) {
  node.send(node.encode(link::MsgType::kStart, link::Start{static_cast<std::uint32_t>(k0), t_ns}));
  node.wait_answered();
  if (node.status().state != link::NodeState::kRunning) throw std::runtime_error("node did not start");
}

}  // namespace vines::host
