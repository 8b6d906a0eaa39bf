// The header of a model image (layout in model_image.hpp), the image's
// size, and the writer of a built model's image.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "vines/bytes/crc32.hpp"
#include "vines/image/codec.hpp"
#include "vines/image/fields.hpp"
#include "vines/model/model.hpp"

namespace vines::image {

inline constexpr std::uint16_t kVersion = 3;  // 2: loop.split_steps; 3: the loop's limits and the radius in S
inline constexpr std::size_t kHeaderBytes = 28;
inline constexpr std::uint8_t kMagic[4] = {'V', 'N', 'M', 'I'};
inline constexpr std::uint8_t kNoLaw = 0xFF;

namespace detail {

template <typename S>
constexpr std::uint8_t scalar_code() {
  static_assert(std::is_same_v<S, double> || std::is_same_v<S, float>, "images hold double or float models");
  return std::is_same_v<S, float> ? 1 : 0;
}
template <typename Dev>
constexpr std::uint8_t law_code() {
  if constexpr (Dev::kKind == DeviceKind::kVines) return static_cast<std::uint8_t>(Dev::kLaw);
  else return kNoLaw;
}

}  // namespace detail

// Bytes of the image of this instance (header + body).
template <typename S, int N, typename Dev>
constexpr std::size_t image_bytes() {
  constexpr detail::Shape sh = detail::shape<S, N, Dev>();
  static_assert(sh.fits, "visit_fields: a Part does not fit its field");
  return kHeaderBytes + sh.body;
}

// The header of an image as written (for tools that describe an image; the
// Loader checks it against its instance). false: fewer than kHeaderBytes or
// no magic.
struct HeaderInfo {
  std::uint16_t version = 0;
  std::uint8_t scalar = 0, scalar_bytes = 0;  // scalar: 0 double, 1 float
  std::uint16_t stories = 0;
  std::uint8_t device = 0, law = kNoLaw;      // DeviceKind, ContactLaw (kNoLaw: no VI NES)
  std::uint32_t length = 0;                   // header + body
  std::uint16_t fields = 0;
  std::uint32_t layout = 0, crc = 0;
};
inline bool read_header(const std::uint8_t* p, std::size_t n, HeaderInfo* out) {
  if (p == nullptr || n < kHeaderBytes || std::memcmp(p, kMagic, 4) != 0) return false;
  out->version = detail::get_u16(p + 4);
  out->scalar = p[6];
  out->scalar_bytes = p[7];
  out->stories = detail::get_u16(p + 8);
  out->device = p[10];
  out->law = p[11];
  out->length = detail::get_u32(p + 12);
  out->fields = detail::get_u16(p + 16);
  out->layout = detail::get_u32(p + 20);
  out->crc = detail::get_u32(p + 24);
  return true;
}

// Writes the image of a built model; returns its size, 0 if cap is too small.
template <typename S, int N, typename Dev>
std::size_t write_image(const Model<S, N, Dev>& m, std::uint8_t* out, std::size_t cap) {
  constexpr detail::Shape sh = detail::shape<S, N, Dev>();
  constexpr std::size_t total = image_bytes<S, N, Dev>();
  static_assert(total <= 0xFFFFFFFFu && sh.fields <= 0xFFFF, "image too large for its header");
  if (out == nullptr || cap < total) return 0;
  std::memcpy(out, kMagic, 4);
  detail::put_u16(out + 4, kVersion);
  out[6] = detail::scalar_code<S>();
  out[7] = static_cast<std::uint8_t>(sizeof(S));
  detail::put_u16(out + 8, static_cast<std::uint16_t>(N));
  out[10] = static_cast<std::uint8_t>(Dev::kKind);
  out[11] = detail::law_code<Dev>();
  detail::put_u32(out + 12, static_cast<std::uint32_t>(total));
  detail::put_u16(out + 16, static_cast<std::uint16_t>(sh.fields));
  detail::put_u16(out + 18, 0);
  detail::put_u32(out + 20, sh.layout);
  detail::BodyWriter<Model<S, N, Dev>> w{&m, out + kHeaderBytes};
  visit_fields<S, N, Dev>(w);
  if (w.pos != sh.body) return 0;  // cannot happen: the sizes come from the same list
  const std::uint32_t crc = link::crc32(out + kHeaderBytes, total - kHeaderBytes, link::crc32(out, 24));
  detail::put_u32(out + 24, crc);
  return total;
}

// Streaming loader: the image arrives in chunks, in order, and is decoded
// straight into the model's storage (no staging buffer the size of the
// image). The model is overwritten from the first body byte on: it is usable
// only once finish() succeeded (ready()), whatever happened before; a
// refused image leaves it unusable (not ready) until a good one loads.
// Refusals are sticky until reset(); messages point into the loader.

}  // namespace vines::image
