// Text into the node's status message (link/node.hpp): fixed buffers, no
// printf on a board.
#pragma once

#include <cstddef>

#include "vines/model/param_error.hpp"

namespace vines::link {

// "field[index]: message" into m (cap bytes, NUL-terminated; no printf on a
// board); returns m.
inline const char* describe(const ParamError& e, char* m, std::size_t cap) {
  std::size_t n = 0;
  auto put = [&](const char* s) {
    for (; *s != '\0' && n + 1 < cap; ++s) m[n++] = *s;
  };
  put(e.field);
  if (e.index >= 0) {
    char digits[12];
    int d = 0;
    for (unsigned v = static_cast<unsigned>(e.index); d == 0 || v != 0; v /= 10) digits[d++] = static_cast<char>('0' + v % 10);
    put("[");
    while (d > 0 && n + 1 < cap) m[n++] = digits[--d];
    put("]");
  }
  put(": ");
  put(e.message);
  m[n] = '\0';
  return m;
}

// s into m (cap bytes), cut to fit, NUL-terminated.
inline void copy_text(const char* s, char* m, std::size_t cap) {
  std::size_t i = 0;
  for (; s[i] != '\0' && i + 1 < cap; ++i) m[i] = s[i];
  m[i] = '\0';
}

}  // namespace vines::link
