// Telemetry lines on the link, written without printf (which would pull in
// newlib's heap): "KEY VALUE" with integers in decimal and doubles as the 16
// hex digits of their bits (exact; the host reads them back bit for bit).
#pragma once

#include <cstdint>
#include <cstring>

#include "vines/hal/port.hpp"

namespace vines::app {

inline void put(const char* s) { hal::link_write(s, std::strlen(s)); }

inline void put_uint(std::uint64_t v) {
  char buf[21];
  char* p = buf + sizeof buf;
  do {
    *--p = static_cast<char>('0' + v % 10u);
    v /= 10u;
  } while (v != 0u);
  hal::link_write(p, static_cast<std::size_t>(buf + sizeof buf - p));
}

inline void put_int(const char* key, std::int64_t v) {
  put("i ");
  put(key);
  put(v < 0 ? " -" : " ");
  put_uint(v < 0 ? 0u - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v));
  put("\n");
}

inline void put_double(const char* key, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  char hex[17];
  for (int i = 0; i < 16; ++i) hex[i] = "0123456789abcdef"[(bits >> (60 - 4 * i)) & 0xFu];
  hex[16] = '\0';
  put("d ");
  put(key);
  put(" ");
  put(hex);
  put("\n");
}

}  // namespace vines::app
