// The firmware's end of the link: a state machine fed bytes and time, that
// runs a plant (the model) one sample at a time and answers with telemetry,
// status and fault reports. Fixed memory, no heap, no exceptions: the same
// code runs in the host's node process and on the microcontroller.
//
// Plant (duck-typed):
//   const char* image_begin(uint32_t total); const char* image_push(const uint8_t*, size_t);
//   const char* image_finish(): the model image, streamed in order (nullptr,
//     or why it is refused: corrupt, truncated, built for another node);
//   bool configure(const NodeConfig&, char* msg, size_t cap): the settings,
//     checked against the model image (false with the reason in msg);
//   void sense(const double* y, int ny): the step's measured floor
//     accelerations (twin estimator; nullptr, 0: none), before init or step;
//   void init(double a0, double f0); void step(double a1, double f1);
//   void read(Telemetry*) (fills n, x, acc_top, energies, particle,
//     step_ticks; flags kGuard when the core's guards acted in the last step);
//   void timing(StepTiming*) (the deadline monitor's counts).
// Sink: void write(const uint8_t*, size_t).
//
// Fault policy (docs/link_protocol.md): frames are checked (COBS, CRC,
// version, type, payload) and sequenced (gaps, duplicates, reordering);
// a sample missing when a later one arrives is interpolated between its
// neighbours; a sample missing at its deadline (k h + grace) is held; a late
// or duplicate sample is dropped; a NaN/inf sample is held; a sample at the
// sensor range is extrapolated (linearly) when that goes further. Every
// frame received, good or bad, is answered by at least one frame carrying rx.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "vines/link/config.hpp"
#include "vines/link/frame.hpp"
#include "vines/link/messages.hpp"
#include "vines/link/mode_outputs.hpp"
#include "vines/link/status_text.hpp"
#include "vines/model/validate.hpp"

namespace vines::link {

// Farthest a sample index or stamp may lead the node, in periods (65 s at
// 1 kHz): beyond it the frame is refused as a protocol fault.
inline constexpr std::uint32_t kMaxLead = 65536;

template <class Plant, class Sink>
class Node {
 public:
  Node(Plant* plant, Sink* sink) : plant_(plant), sink_(sink) {}

  // One byte from the link, at local time local_ns (0 with a virtual clock:
  // then time comes from the frames' stamps).
  void on_byte(std::uint8_t b, std::uint64_t local_ns) {
    const DecodeResult r = dec_.push(b);
    if (r == DecodeResult::kNone) return;
    ++status_.rx;
    const std::uint32_t sent = tx_frames_;
    local_ = local_ns;
    advance_clock(local_ns, 0);
    if (r == DecodeResult::kFrame) on_frame(dec_.frame());
    else fault(decode_fault(r), 0, 1);
    if (tx_frames_ == sent) send_status();
  }

  // A status unasked: a board that has just powered up says it listens (a
  // UART drops what came before it was enabled; the bench waits for this).
  void announce() { send_status(); }

  // Runs deadlines that have passed by local time local_ns (real-time clock).
  void poll(std::uint64_t local_ns) { advance_clock(local_ns, 0); }

  // Local time of the next deadline (UINT64_MAX if none), for the timer.
  std::uint64_t next_deadline_local() const {
    if (status_.state != NodeState::kRunning || !initialised_) return UINT64_MAX;
    const auto d = static_cast<std::int64_t>(deadline(status_.next_k)) - offset_;
    return d > 0 ? static_cast<std::uint64_t>(d) : 0;
  }

  const Status& status() const { return status_; }
  bool stopped() const { return status_.state == NodeState::kStopped; }

 private:
  static FaultCode decode_fault(DecodeResult r) {
    switch (r) {
      case DecodeResult::kBadCrc: return FaultCode::kCrc;
      case DecodeResult::kBadVersion: return FaultCode::kVersion;
      case DecodeResult::kBadType: return FaultCode::kType;
      default: return FaultCode::kFraming;
    }
  }

  // ---- time -------------------------------------------------------------
  std::uint64_t period_ns() const { return static_cast<std::uint64_t>(std::llround(1e9 * h_)); }
  std::uint64_t due(std::uint32_t k) const { return static_cast<std::uint64_t>(std::llround(1e9 * h_ * k)); }
  std::uint64_t deadline(std::uint32_t k) const {
    return due(k) + static_cast<std::uint64_t>(std::llround(1e9 * h_ * cfg_.grace_periods));
  }

  // Bench time is the later of the local clock (mapped at START) and the
  // newest frame stamp; deadlines strictly before it are served by holding.
  // A stamp more than kMaxLead periods ahead is refused (false): catching up
  // to it would hold the model through that many steps at once.
  bool advance_clock(std::uint64_t local_ns, std::uint64_t stamp_ns) {
    if (status_.state != NodeState::kRunning) return true;
    if (stamp_ns > now_ && (stamp_ns - now_) / period_ns() > kMaxLead) return false;
    const std::int64_t mapped = static_cast<std::int64_t>(local_ns) + offset_;
    std::uint64_t now = local_ns && mapped > 0 ? static_cast<std::uint64_t>(mapped) : 0;
    if (stamp_ns > now) now = stamp_ns;
    if (now > now_) now_ = now;
    if (!initialised_) return true;
    const std::uint64_t silent = now_ > last_rx_ns_ ? now_ - last_rx_ns_ : 0;
    if (!stalled_ && silent > static_cast<std::uint64_t>(cfg_.stall_periods * 1e9 * h_)) {
      stalled_ = true;
      fault(FaultCode::kStall, status_.next_k, static_cast<std::uint32_t>(silent / period_ns()));
    }
    while (deadline(status_.next_k) < now_) {
      fault(FaultCode::kHeld, status_.next_k, 1);
      apply(a_last_, aux_last_, kNan, kHeld, false);
    }
    return true;
  }

  // ---- frames -----------------------------------------------------------
  void on_frame(const Frame& f) {
    if (!sequence_ok(f.seq)) return;
    switch (f.type) {
      case MsgType::kConfigure: {
        ConfigureChunk c;
        if (!decode(f.payload, f.length, &c)) return fault(FaultCode::kType, f.seq, 1);
        return on_configure(c);
      }
      case MsgType::kStart: {
        Start s;
        if (!decode(f.payload, f.length, &s)) return fault(FaultCode::kType, f.seq, 1);
        return on_start(s);
      }
      case MsgType::kSample: {
        Sample s;
        if (!decode(f.payload, f.length, &s)) return fault(FaultCode::kType, f.seq, 1);
        if (status_.state != NodeState::kRunning) return fault(FaultCode::kProtocol, s.k, 1);
        if (!advance_clock(0, s.t_ns)) return fault(FaultCode::kProtocol, s.k, 1);
        last_rx_ns_ = now_;
        stalled_ = false;
        return on_sample(s);
      }
      case MsgType::kStop:
        if (status_.state == NodeState::kRunning) status_.state = NodeState::kStopped;
        return send_status();
      default:
        return fault(FaultCode::kType, f.seq, 1);  // a node -> bench message
    }
  }

  // Sequence numbers of bench frames: false for a duplicate (dropped).
  bool sequence_ok(std::uint16_t seq) {
    if (!have_seq_) {
      have_seq_ = true;
      last_seq_ = seq;
      seen_ = 1;
      return true;
    }
    const auto d = static_cast<std::int16_t>(static_cast<std::uint16_t>(seq - last_seq_));
    if (d > 0) {
      if (d > 1) fault(FaultCode::kSeqGap, static_cast<std::uint16_t>(last_seq_ + 1), static_cast<std::uint32_t>(d - 1));
      seen_ = d >= 64 ? 1 : (seen_ << d) | 1;
      last_seq_ = seq;
      return true;
    }
    const int back = -d;
    if (d == 0 || (back < 64 && ((seen_ >> back) & 1u))) {
      fault(FaultCode::kDuplicate, seq, 1);
      return false;
    }
    if (back < 64) seen_ |= std::uint64_t{1} << back;
    fault(FaultCode::kReordered, seq, 1);
    return true;
  }

  void on_configure(const ConfigureChunk& c) {
    if (status_.state == NodeState::kRunning) return fault(FaultCode::kProtocol, 0, 1);
    if (c.part == ConfigPart::kModelImage) return on_image(c);
    if (c.total > kMaxConfigBlob || (c.offset != 0 && (c.offset != blob_len_ || c.blob_crc != blob_crc_)))
      return fault(FaultCode::kConfig, c.offset, 1);
    if (c.offset == 0) blob_crc_ = c.blob_crc;
    for (std::uint16_t i = 0; i < c.length; ++i) blob_[c.offset + i] = c.data[i];
    blob_len_ = c.offset + c.length;
    if (blob_len_ < c.total) return;
    blob_len_ = 0;
    status_.message[0] = '\0';
    status_.state = NodeState::kBooted;
    NodeConfig cfg;
    const char* why = nullptr;
    if (crc32(blob_, c.total) != c.blob_crc) why = "configuration blob: CRC mismatch";
    else if (!decode(blob_, c.total, &cfg)) why = "configuration blob: malformed";
    else why = validate_node(cfg);
    const ParamError scene = why ? ParamError{} : validate(cfg.scene);
    if (why) copy_message(why);
    else if (!scene.ok()) why = describe(scene, status_.message, sizeof status_.message);
    else if (!plant_->configure(cfg, status_.message, sizeof status_.message)) why = status_.message;
    if (why) {
      fault(FaultCode::kConfig, 0, 1);
      return send_status();  // with the reason
    }
    cfg_ = cfg;
    h_ = 1.0 / cfg.scene.loop.sensor_rate_hz;
    status_.state = NodeState::kConfigured;
    send_status();
  }

  // A chunk of the model image: streamed to the plant in order (it decodes
  // into the model's own storage, so no buffer the size of the image). A
  // refused image leaves the node unconfigured, with the reason.
  void on_image(const ConfigureChunk& c) {
    const char* why = nullptr;
    if (c.offset == 0) {
      status_.state = NodeState::kBooted;
      status_.message[0] = '\0';
      image_len_ = 0;
      image_crc_ = c.blob_crc;
      image_failed_ = false;
      why = plant_->image_begin(c.total);
    } else if (image_failed_) {
      return;  // refused already: the rest of it is ignored
    } else if (c.offset != image_len_ || c.blob_crc != image_crc_) {
      why = "model image: chunks out of order or from another image";
    }
    if (!why) why = plant_->image_push(c.data, c.length);
    image_len_ = c.offset + c.length;
    if (!why && image_len_ == c.total) why = plant_->image_finish();
    if (!why && image_len_ < c.total) return;
    if (why) {
      image_failed_ = true;
      copy_message(why);
      fault(FaultCode::kConfig, c.offset, 1);
    }
    send_status();
  }

  void on_start(const Start& s) {
    if (status_.state != NodeState::kConfigured && status_.state != NodeState::kStopped)
      return fault(FaultCode::kProtocol, s.k0, 1);
    status_.state = NodeState::kRunning;
    status_.cold_start = 0;
    status_.next_k = s.k0;
    initialised_ = false;
    stalled_ = false;
    now_ = s.t_ns;
    offset_ = local_ ? static_cast<std::int64_t>(s.t_ns) - static_cast<std::int64_t>(local_) : 0;
    last_rx_ns_ = s.t_ns;
    filled_ = 0;
    outputs_.reset(cfg_, h_);
    send_status();
  }

  void on_sample(const Sample& s) {
    const std::uint32_t e = status_.next_k;
    if (initialised_ && s.k < e) {
      const std::uint32_t back = e - 1 - s.k;
      const bool filled = back < 64 && ((filled_ >> back) & 1u);
      return fault(filled ? FaultCode::kLate : FaultCode::kDuplicate, s.k, 1);
    }
    if (s.k - e > kMaxLead) return fault(FaultCode::kProtocol, s.k, 1);
    std::uint16_t flags = 0;
    double a = s.ag;
    if (!std::isfinite(a)) {
      fault(FaultCode::kNonFinite, s.k, 1);
      a = initialised_ ? a_last_ : 0.0;
      flags |= kNonFinite;
    } else if (cfg_.sensor_range_mps2 > 0 && std::fabs(a) >= cfg_.sensor_range_mps2) {
      fault(FaultCode::kSaturated, s.k, 1);
      flags |= kSaturated;
      const double ext = 2 * a_last_ - a_prev_last_;
      if (initialised_ && ext * a > 0 && std::fabs(ext) > std::fabs(a)) a = ext;
    }
    double aux = s.aux;
    if (!std::isfinite(aux) && cfg_.mode != NodeMode::kReplay) {
      aux = aux_last_;
      flags |= kAuxMissing;
    }
    // The measured floors: all finite, or the step has none.
    const double* y = s.ny > 0 ? s.y : nullptr;
    for (int i = 0; y && i < s.ny; ++i)
      if (!std::isfinite(s.y[i])) y = nullptr, flags |= kAuxMissing;
    if (!initialised_) {
      status_.next_k = s.k;
      return apply(a, aux, s.table_x, flags, true, y, y ? s.ny : 0);
    }
    // Samples missing before this one: interpolated towards it (the table
    // not measured there).
    const std::uint32_t gap = s.k - e;
    const double a0 = a_last_;
    for (std::uint32_t i = 1; i <= gap; ++i)
      apply(a0 + (a - a0) * i / (gap + 1.0), aux_last_, kNan, kInterpolated | kAuxMissing, false);
    apply(a, aux, s.table_x, flags, true, y, y ? s.ny : 0);
  }

  // ---- stepping ---------------------------------------------------------
  // One step on ground acceleration a, the measured value aux (twin:
  // acceleration, hybrid: force), hybrid, the measured table displacement xm
  // (NaN: not measured) and, twin, the measured floors y (nullptr: none).
  void apply(double a, double aux, double xm, std::uint16_t flags, bool real, const double* y = nullptr,
             int ny = 0) {
    const std::uint32_t k = status_.next_k;
    const double f = cfg_.mode == NodeMode::kHybrid ? aux : 0.0;
    plant_->sense(y, ny);
    if (!initialised_) {
      plant_->init(a, f);
      initialised_ = true;
      a_prev_last_ = a;
    } else {
      plant_->step(a, f);
      a_prev_last_ = a_last_;
    }
    a_last_ = a;
    aux_last_ = aux;
    filled_ = (filled_ << 1) | (real ? 0u : 1u);
    ++status_.steps;
    status_.next_k = k + 1;

    Telemetry& t = tel_;
    t = Telemetry{};
    t.k = k;
    plant_->read(&t);
    t.rx = status_.rx;
    t.ag = a;
    t.flags = static_cast<std::uint16_t>(t.flags | flags);
    if (cfg_.mode == NodeMode::kTwin) outputs_.twin(cfg_, h_, &t, aux, (flags & kAuxMissing) == 0);
    if (cfg_.mode == NodeMode::kHybrid) t.aux = outputs_.command(cfg_, h_, t.x[t.n - 1], xm, &t);
    send(MsgType::kTelemetry, t);
  }

  // ---- output -----------------------------------------------------------
  template <class Msg>
  void send(MsgType type, const Msg& m) {
    std::uint8_t payload[kMaxPayload];
    const std::size_t n = encode(m, payload, sizeof payload);
    std::uint8_t wire[kMaxWire];
    const std::size_t w = encode_frame(type, tx_seq_++, payload, n, wire, sizeof wire);
    if (w == 0) return;
    ++tx_frames_;
    sink_->write(wire, w);
  }
  void send_status() {
    plant_->timing(&status_.timing);
    send(MsgType::kStatus, status_);
  }
  void fault(FaultCode code, std::uint32_t k, std::uint32_t count) {
    ++status_.faults[static_cast<int>(code)];
    Fault f;
    f.rx = status_.rx;
    f.code = code;
    f.k = k;
    f.count = count;
    send(MsgType::kFault, f);
  }
  void copy_message(const char* s) { copy_text(s, status_.message, sizeof status_.message); }

  Plant* plant_;
  Sink* sink_;
  Decoder dec_;
  Status status_;
  NodeConfig cfg_;
  Telemetry tel_;
  double h_ = 1e-3;
  // sequence of received frames
  bool have_seq_ = false;
  std::uint16_t last_seq_ = 0, tx_seq_ = 0;
  std::uint64_t seen_ = 0;    // bit i: seq last_seq_ - i was received
  std::uint32_t tx_frames_ = 0;
  // configuration assembly
  std::uint8_t blob_[kMaxConfigBlob] = {};
  std::size_t blob_len_ = 0;
  std::uint32_t blob_crc_ = 0;
  // model image
  std::uint32_t image_len_ = 0, image_crc_ = 0;
  bool image_failed_ = false;
  // run
  bool initialised_ = false, stalled_ = false;
  std::uint64_t now_ = 0, local_ = 0, last_rx_ns_ = 0;  // bench clock now; local clock at the last byte
  std::int64_t offset_ = 0;                             // bench clock - local clock (real time)
  std::uint64_t filled_ = 0;  // bit i: step next_k - 1 - i was filled (held or interpolated)
  double a_last_ = 0, a_prev_last_ = 0, aux_last_ = 0;
  ModeOutputs outputs_;  // twin alarms, hybrid table command
  static constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace vines::link
