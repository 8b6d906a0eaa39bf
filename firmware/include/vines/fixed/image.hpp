// The fixed-point model image (issue 34): what the bench sends a
// fixed-point node (`vines hil --node qemu:cortex-m3`), built on the host
// from the scene, loaded by the board into static storage: the board builds
// no model and has no floating point in its step.
//
// Layout, little-endian:
//   0  magic "VNFI"        4  version u16       6  device kind u8
//   7  law u8 (0xFF none)  8  stories u8        9  fraction bits u8
//   10 moments u8          11 alignment u8      12 body bytes u32
//   16 CRC-32 of the body u32                   20 body
// The body is the model's own bytes (FixedNodeModel, fixed/node_model.hpp):
// integers, Q values, Gains and a few doubles, laid out alike by every
// target the project builds (x86-64 and 32-bit ARM: 8-byte doubles aligned
// to 8, Eigen's 16-byte static alignment, asserted in node_main.cpp), so
// no field is converted; a header whose size, alignment or instance
// (device, law, stories, format) differs from the loader's is refused, and
// the bit-for-bit HIL tests (firmware/app/CMakeLists.txt) hold the rest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vines/bytes/crc32.hpp"
#include "vines/bytes/wire.hpp"

namespace vines::fixed {

inline constexpr std::uint8_t kImageMagic[4] = {'V', 'N', 'F', 'I'};
inline constexpr std::uint16_t kImageVersion = 1;
inline constexpr std::size_t kImageHeaderBytes = 20;

// What identifies the instance an image was built for.
struct ImageKind {
  std::uint8_t device = 0, law = 0xFF, stories = 0, bits = 0, moments = 0, align = 0;
  std::uint32_t body = 0;
};

inline bool is_fixed_image(const std::uint8_t* p, std::size_t n) {
  return n >= 4 && std::memcmp(p, kImageMagic, 4) == 0;
}

// Writes the image of the model bytes (body) of kind k into out (cap bytes
// at least kImageHeaderBytes + k.body); its size.
inline std::size_t write_image(const ImageKind& k, const void* body, std::uint8_t* out, std::size_t cap) {
  if (cap < kImageHeaderBytes + k.body) return 0;
  const auto* b = static_cast<const std::uint8_t*>(body);
  link::Writer w(out, cap);
  w.bytes(kImageMagic, 4);
  w.u16(kImageVersion);
  for (std::uint8_t v : {k.device, k.law, k.stories, k.bits, k.moments, k.align}) w.u8(v);
  w.u32(k.body);
  w.u32(link::crc32(b, k.body));
  w.bytes(b, k.body);
  return w.ok() ? w.size() : 0;
}

// Streams an image into the model bytes of kind `want` at `body` (static
// storage): the header checked first, the body copied as it arrives, its
// CRC at the end. Each call returns nullptr or why the image is refused.
class ImageLoader {
 public:
  ImageLoader(const ImageKind& want, void* body) : want_(want), body_(static_cast<std::uint8_t*>(body)) {}

  void reset() {
    got_ = 0;
    ready_ = false;
    crc_ = 0;
  }
  bool ready() const { return ready_; }

  const char* push(const std::uint8_t* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      if (got_ < kImageHeaderBytes) {
        header_[got_++] = p[i];
        if (got_ == kImageHeaderBytes) {
          if (const char* why = check_header()) return why;
        }
        continue;
      }
      const std::size_t at = got_ - kImageHeaderBytes;
      if (at >= want_.body) return "fixed-point model image: longer than its header says";
      body_[at] = p[i];
      ++got_;
    }
    return nullptr;
  }

  const char* finish() {
    ready_ = false;
    if (got_ != kImageHeaderBytes + want_.body) return "fixed-point model image: truncated";
    if (link::crc32(body_, want_.body) != crc_) return "fixed-point model image: CRC mismatch (corrupted)";
    ready_ = true;
    return nullptr;
  }

 private:
  const char* check_header() {
    if (!is_fixed_image(header_, kImageHeaderBytes))
      return "model image: not a fixed-point model image (this node runs Q3.28: loop.scalar = \"fixed\")";
    link::Reader r(header_ + 4, kImageHeaderBytes - 4);
    if (r.u16() != kImageVersion) return "fixed-point model image: another version than this node's";
    if (r.u8() != want_.device) return "device.kind: differs from the model image's";
    if (r.u8() != want_.law) return "vines.law: differs from the model image's";
    if (r.u8() != want_.stories) return "frame.stories: differs from the model image's";
    const std::uint8_t bits = r.u8(), moments = r.u8(), align = r.u8();
    if (bits != want_.bits || moments != want_.moments || align != want_.align)
      return "fixed-point model image: another format than this node's (fraction bits, moments or alignment)";
    if (r.u32() != want_.body) return "fixed-point model image: its model's size differs from this node's";
    crc_ = r.u32();
    return nullptr;
  }

  ImageKind want_;
  std::uint8_t* body_;
  std::uint8_t header_[kImageHeaderBytes] = {};
  std::size_t got_ = 0;
  std::uint32_t crc_ = 0;
  bool ready_ = false;
};

}  // namespace vines::fixed
