// Link frames (docs/link_protocol.md). Before stuffing, a frame is
//   version u8 | type u8 | seq u16 | payload (0..kMaxPayload bytes) | crc32 u32
// little-endian, the CRC over everything before it; on the wire it is COBS
// encoded and followed by one 0x00 delimiter. The Decoder takes bytes one at a
// time from any stream (UART interrupt, pipe, socket) with fixed buffers, and
// never needs more than one frame of memory.
#pragma once

#include <cstddef>
#include <cstdint>

#include "vines/bytes/crc32.hpp"
#include "vines/bytes/wire.hpp"
#include "vines/link/cobs.hpp"

namespace vines::link {

inline constexpr std::uint8_t kProtocolVersion = 5;
inline constexpr std::size_t kHeaderBytes = 4, kCrcBytes = 4;
inline constexpr std::size_t kMaxPayload = 512;  // a 40-story twin TELEMETRY is 499
inline constexpr std::size_t kMaxRaw = kHeaderBytes + kMaxPayload + kCrcBytes;
// Encoded frame with its delimiter: what a sender's buffer must hold.
inline constexpr std::size_t kMaxWire = cobs_max_encoded(kMaxRaw) + 1;

enum class MsgType : std::uint8_t {
  kConfigure = 1,  // bench -> node: a chunk of the configuration blob
  kStart = 2,      // bench -> node: start at a sample index
  kSample = 3,     // bench -> node: one sensor sample
  kStop = 4,       // bench -> node: end of run
  kTelemetry = 16, // node -> bench: outputs of one step
  kStatus = 17,    // node -> bench: state and counters
  kFault = 18,     // node -> bench: one detected fault
};

inline bool known_type(std::uint8_t t) {
  return (t >= 1 && t <= 4) || (t >= 16 && t <= 18);
}

struct Frame {
  std::uint8_t version = 0;
  MsgType type = MsgType::kStop;
  std::uint16_t seq = 0;
  const std::uint8_t* payload = nullptr;  // points into the decoder's buffer
  std::size_t length = 0;
};

// Writes the wire form (COBS + 0x00) of one frame into out; returns its size,
// or 0 if the payload is too long or out too small.
inline std::size_t encode_frame(MsgType type, std::uint16_t seq, const std::uint8_t* payload, std::size_t n,
                                std::uint8_t* out, std::size_t cap) {
  if (n > kMaxPayload) return 0;
  std::uint8_t raw[kMaxRaw];
  Writer w(raw, sizeof raw);
  w.u8(kProtocolVersion);
  w.u8(static_cast<std::uint8_t>(type));
  w.u16(seq);
  w.bytes(payload, n);
  w.u32(crc32(raw, w.size()));
  const std::size_t e = cobs_encode(raw, w.size(), out, cap);
  if (e == 0 || e >= cap) return 0;
  out[e] = 0;
  return e + 1;
}

// What the decoder made of the bytes up to a delimiter.
enum class DecodeResult : std::uint8_t {
  kNone,       // no delimiter yet (byte stored)
  kFrame,      // a valid frame: see frame()
  kEmpty,      // a delimiter with nothing before it
  kOversize,   // more bytes than any frame before a delimiter (dropped up to it)
  kBadCobs,    // not valid COBS
  kTooShort,   // shorter than header + CRC
  kBadCrc,     // CRC mismatch
  kBadVersion, // CRC good, another protocol version
  kBadType,    // CRC good, unknown message type
};

inline bool is_error(DecodeResult r) { return r != DecodeResult::kNone && r != DecodeResult::kFrame; }

class Decoder {
 public:
  DecodeResult push(std::uint8_t b) {
    if (b != 0) {
      if (len_ < sizeof enc_) enc_[len_++] = b;
      else overflow_ = true;
      return DecodeResult::kNone;
    }
    const std::size_t n = len_;
    const bool over = overflow_;
    len_ = 0;
    overflow_ = false;
    if (over) return DecodeResult::kOversize;
    if (n == 0) return DecodeResult::kEmpty;
    const long d = cobs_decode(enc_, n, raw_, sizeof raw_);
    if (d < 0) return DecodeResult::kBadCobs;
    const auto m = static_cast<std::size_t>(d);
    if (m < kHeaderBytes + kCrcBytes) return DecodeResult::kTooShort;
    Reader crc(raw_ + m - kCrcBytes, kCrcBytes);
    if (crc.u32() != crc32(raw_, m - kCrcBytes)) return DecodeResult::kBadCrc;
    Reader r(raw_, m - kCrcBytes);
    frame_.version = r.u8();
    const std::uint8_t type = r.u8();
    frame_.seq = r.u16();
    frame_.payload = raw_ + kHeaderBytes;
    frame_.length = m - kHeaderBytes - kCrcBytes;
    if (frame_.version != kProtocolVersion) return DecodeResult::kBadVersion;
    if (!known_type(type)) return DecodeResult::kBadType;
    frame_.type = static_cast<MsgType>(type);
    return DecodeResult::kFrame;
  }
  // The last valid frame; its payload lives until the next push().
  const Frame& frame() const { return frame_; }

 private:
  std::uint8_t enc_[cobs_max_encoded(kMaxRaw)];
  std::uint8_t raw_[kMaxRaw];
  std::size_t len_ = 0;
  bool overflow_ = false;
  Frame frame_;
};

}  // namespace vines::link
