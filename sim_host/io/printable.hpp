// A message fit for a terminal: it may quote bytes of a user's file (a bad
// token, a header line), which must neither drive the terminal (escape
// sequences) nor flood it (a 10 MB token). Control bytes and bytes that are
// not UTF-8 become \xNN (a newline or tab stays); each line is cut after
// `line_max` bytes, saying how many more it had.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace vines::host {

inline std::string printable(std::string_view s, std::size_t line_max = 400) {
  std::string out;
  std::size_t in_line = 0, cut = 0;
  auto flush_cut = [&] {
    if (cut > 0) out += "... (" + std::to_string(cut) + " more bytes)";
    cut = 0;
  };
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '\n') {
      flush_cut();
      out += '\n';
      in_line = 0;
      ++i;
      continue;
    }
    // The length of a valid UTF-8 sequence at i (0: not one).
    std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
    for (std::size_t k = 1; k < n; ++k)
      if (i + k >= s.size() || (static_cast<unsigned char>(s[i + k]) >> 6) != 0x2) n = 0;
    if (in_line >= line_max) {
      cut += n ? n : 1;
      i += n ? n : 1;
      continue;
    }
    if (n == 0 || (n == 1 && ((c < 0x20 && c != '\t') || c == 0x7f))) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
      in_line += 4;
      ++i;
      continue;
    }
    out.append(s.data() + i, n);
    in_line += n;
    i += n;
  }
  flush_cut();
  return out;
}

}  // namespace vines::host
