// Consistent Overhead Byte Stuffing (Cheshire & Baker 1999): a frame of any
// bytes becomes a frame without 0x00, so 0x00 can delimit frames on a byte
// stream and a receiver resynchronises at the next 0x00 after any garbage.
// Overhead: at most one byte per 254, plus one.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vines::link {

// Worst-case encoded size of n bytes (without the 0x00 delimiter).
constexpr std::size_t cobs_max_encoded(std::size_t n) { return n + n / 254 + 1; }

// Encodes in[0..n) into out (capacity cap). Returns the encoded length, or 0
// if it does not fit.
inline std::size_t cobs_encode(const std::uint8_t* in, std::size_t n, std::uint8_t* out, std::size_t cap) {
  if (cap < cobs_max_encoded(n)) return 0;
  std::size_t code_at = 0, o = 1;
  std::uint8_t code = 1;
  for (std::size_t i = 0; i < n; ++i) {
    if (in[i] == 0) {
      out[code_at] = code;
      code_at = o++;
      code = 1;
    } else {
      out[o++] = in[i];
      if (++code == 0xFF) {
        out[code_at] = code;
        code_at = o++;
        code = 1;
      }
    }
  }
  out[code_at] = code;
  return o;
}

// Decodes in[0..n) (no 0x00 inside) into out (capacity cap). Returns the
// decoded length, or -1 if the input is not valid COBS (a 0x00, or a code that
// runs past the end) or does not fit.
inline long cobs_decode(const std::uint8_t* in, std::size_t n, std::uint8_t* out, std::size_t cap) {
  std::size_t i = 0, o = 0;
  while (i < n) {
    const std::uint8_t code = in[i++];
    if (code == 0) return -1;
    const std::size_t run = code - 1u;
    if (run > n - i || o + run > cap) return -1;
    for (std::size_t k = 0; k < run; ++k) {
      if (in[i] == 0) return -1;
      out[o++] = in[i++];
    }
    // A zero follows every block but a full one (0xFF) and the last.
    if (code != 0xFF && i < n) {
      if (o >= cap) return -1;
      out[o++] = 0;
    }
  }
  return static_cast<long>(o);
}

}  // namespace vines::link
