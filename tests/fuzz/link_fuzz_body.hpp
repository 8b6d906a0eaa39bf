// What the link fuzzers run on each input: the bytes go through a Decoder
// (every frame's payload through every message decoder) and through a whole
// Node with a toy plant, so the configuration assembly, sequencing, deadline
// and fault paths see arbitrary input too. Used by the libFuzzer target
// (link_decoder_fuzz.cpp) and by the deterministic mutation test (test_link_fuzz.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "vines/link/node.hpp"

namespace vines::link::fuzz {

// A plant that only echoes its input: the node logic is what is under test.
struct ToyPlant {
  int n = 1;
  double a = 0, f = 0;
  std::uint32_t image_bytes = 0;
  const char* image_begin(std::uint32_t) {
    image_bytes = 0;
    return nullptr;
  }
  const char* image_push(const std::uint8_t*, std::size_t len) {
    image_bytes += static_cast<std::uint32_t>(len);
    return image_bytes > 4096 ? "model image: too long for the toy" : nullptr;
  }
  const char* image_finish() { return nullptr; }
  void timing(StepTiming* t) const { t->counter_hz = 1; }
  bool configure(const NodeConfig& c, char* msg, std::size_t cap) {
    if (!(c.scene.loop.sensor_rate_hz > 0 && c.scene.loop.sensor_rate_hz <= 1e6)) {
      if (cap) msg[0] = '\0';
      return false;
    }
    n = c.scene.frame.stories;
    return true;
  }
  void sense(const double*, int) {}
  void init(double a0, double f0) { a = a0, f = f0; }
  void step(double a1, double f1) { a = a1, f = f1; }
  void read(Telemetry* t) const {
    t->n = static_cast<std::uint8_t>(n);
    for (int i = 0; i < n; ++i) t->x[i] = a;
    t->acc_top = f;
  }
};

// Checks what comes out: every frame the node writes must decode.
struct CheckingSink {
  Decoder dec;
  std::size_t frames = 0, bad = 0;
  void write(const std::uint8_t* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      const DecodeResult r = dec.push(p[i]);
      if (r == DecodeResult::kFrame) ++frames;
      else if (r != DecodeResult::kNone) ++bad;
    }
  }
};

// Structured input (first byte odd): records of type u8 | seq-step u8 |
// length u8 | payload, each framed with a valid CRC, so that the node's message
// handling sees arbitrary payloads that pass the frame checks.
inline std::size_t framed(const std::uint8_t* data, std::size_t size, std::uint8_t* out, std::size_t cap) {
  std::size_t i = 1, o = 0;
  std::uint16_t seq = 0;
  while (i + 3 <= size) {
    const std::uint8_t type = data[i], step = data[i + 1];
    std::size_t len = data[i + 2];
    i += 3;
    if (len > size - i) len = size - i;
    seq = static_cast<std::uint16_t>(seq + (step < 200 ? 1 : step));  // mostly in order
    const std::size_t w = encode_frame(static_cast<MsgType>(type), seq, data + i, len, out + o, cap - o);
    if (w == 0) break;
    o += w;
    i += len;
  }
  return o;
}

// Returns the number of node output frames that failed to decode (must be 0).
inline std::size_t run_one(const std::uint8_t* data, std::size_t size) {
  static std::uint8_t built[1 << 16];
  if (size > 0 && (data[0] & 1)) {
    size = framed(data, size < 8192 ? size : 8192, built, sizeof built);
    data = built;
  }
  static Decoder dec;  // static: big buffers off the stack, state carried like a live link
  dec = Decoder{};
  for (std::size_t i = 0; i < size; ++i) {
    if (dec.push(data[i]) != DecodeResult::kFrame) continue;
    const Frame& f = dec.frame();
    ConfigureChunk c;
    Start s;
    Sample m;
    Telemetry t;
    Status st;
    Fault ft;
    NodeConfig cfg;
    (void)decode(f.payload, f.length, &c);
    (void)decode(f.payload, f.length, &s);
    (void)decode(f.payload, f.length, &m);
    (void)decode(f.payload, f.length, &t);
    (void)decode(f.payload, f.length, &st);
    (void)decode(f.payload, f.length, &ft);
    (void)decode(f.payload, f.length, &cfg);
  }
  static ToyPlant plant;
  static CheckingSink sink;
  using N = Node<ToyPlant, CheckingSink>;
  static N node(&plant, &sink);
  node = N(&plant, &sink);
  sink = CheckingSink{};
  // Time advances with the input: real-time paths (deadlines, stalls) too.
  std::uint64_t local = 1;
  for (std::size_t i = 0; i < size; ++i) {
    node.on_byte(data[i], local);
    local += 1000ull * (data[i] & 0x0F);
    if ((i & 31) == 31) node.poll(local);
  }
  return sink.bad;
}

}  // namespace vines::link::fuzz
