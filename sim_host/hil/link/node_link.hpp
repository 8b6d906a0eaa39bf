// The bench's end of the link to one node process: frames encoded with the
// bench's sequence numbers, sent, and the node's answers (telemetry, faults,
// status) read and dispatched; configure and start a fresh node.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/hil/link/transport.hpp"
#include "sim_host/hil/options.hpp"
#include "vines/link/config.hpp"
#include "vines/link/frame.hpp"
#include "vines/link/messages.hpp"

namespace vines::host {

using HilClock = std::chrono::steady_clock;

double seconds_since(HilClock::time_point t0);

// One node (a process, or a node on TCP) and the bench's end of its link.
class NodeLink {
 public:
  // Starts the node (opt.node, its image or command) or connects to it
  // (tcp:HOST:PORT); its fault messages go to *faults, each with this
  // node's life to *fault_life.
  NodeLink(const HilOptions& opt, long long life, std::vector<link::Fault>* faults,
           std::vector<long long>* fault_life);

  std::uint16_t next_seq() const { return seq_; }

  // Encodes one frame (seq taken now) without sending it.
  template <class Msg>
  std::vector<std::uint8_t> encode(link::MsgType type, const Msg& m) {
    std::uint8_t payload[link::kMaxPayload];
    const std::size_t n = link::encode(m, payload, sizeof payload);
    std::vector<std::uint8_t> w(link::kMaxWire);
    w.resize(link::encode_frame(type, seq_++, payload, n, w.data(), w.size()));
    return w;
  }
  std::vector<std::uint8_t> encode_empty(link::MsgType type);

  void send(const std::vector<std::uint8_t>& bytes);
  // Reads and dispatches what the node sent within timeout_s.
  void pump(double timeout_s);
  // Waits for the status a node sends unasked when it starts (a board once
  // its UART is on: what came before is lost; docs/link_protocol.md), but
  // on a serial line, whose node started before the bench opened it.
  void await_announce();
  // Waits until at most `in_flight` frames sent are still unanswered (0:
  // lock step).
  void wait_answered(std::uint32_t in_flight = 0);

  std::function<void(const link::Telemetry&, double)> on_telemetry;
  const link::Status& status() const { return status_; }
  // The node's first status said it had just powered up (state lost).
  bool first_cold_start() const { return first_cold_start_; }
  long long bad_frames() const { return bad_frames_; }
  long long statuses() const { return statuses_; }  // status messages received
  const std::string& name() const { return name_; }
  int process() const { return link_->process(); }  // the node's process here, or -1
  void set_epoch(HilClock::time_point t0) { t0_ = t0; }
  // Kills the node, then reads what it had sent.
  void kill();
  int finish() { return link_->finish(opt_.timeout_s); }

 private:
  static std::vector<std::string> argv(const HilOptions& opt);
  static std::unique_ptr<NodeTransport> open(const HilOptions& opt);
  // Reads and dispatches what came within timeout_s; false once the pipe ended.
  bool read(double timeout_s);
  std::runtime_error gone(const std::string& tail);

  const HilOptions& opt_;
  long long life_;
  std::vector<link::Fault>* faults_;
  std::vector<long long>* fault_life_;
  std::string name_;
  std::unique_ptr<NodeTransport> link_;
  link::Decoder dec_;
  std::vector<std::uint8_t> buf_;
  std::uint16_t seq_ = 0;
  std::uint32_t delimiters_ = 0, acked_ = 0;
  link::Status status_;
  long long statuses_ = 0, bad_frames_ = 0;
  bool first_cold_start_ = false;
  HilClock::time_point t0_ = HilClock::now();
};

// Configures a fresh node: the model image (if any), then the settings.
void configure(NodeLink& node, const link::NodeConfig& cfg, const std::vector<std::uint8_t>& image);

// Starts a configured node at sample k0 (bench clock t_ns).
void start(NodeLink& node, long long k0, std::uint64_t t_ns);

}  // namespace vines::host
