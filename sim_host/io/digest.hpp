// A digest of texts and files (FNV-1a, 64 bits): the same on every build and
// machine, for fingerprints of what outputs come from (a sweep's plan and
// records, a run's scene) and the checksum of each line of a sweep's log.
// Not cryptographic: it tells changed inputs and damaged lines, not forgeries.
#pragma once

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

namespace vines::host {

class Digest {
 public:
  // A text, then a separator: "ab","c" differs from "a","bc".
  void add(const std::string& text) {
    for (unsigned char c : text) h_ = (h_ ^ c) * 0x100000001b3ULL;
    h_ = (h_ ^ 0xff) * 0x100000001b3ULL;
  }
  // A file's bytes (false, and nothing added, if it cannot be read).
  bool add_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    char buf[1 << 16];
    while (f.read(buf, sizeof buf) || f.gcount() > 0) {
      for (std::streamsize i = 0; i < f.gcount(); ++i) h_ = (h_ ^ static_cast<unsigned char>(buf[i])) * 0x100000001b3ULL;
      if (!f) break;
    }
    h_ = (h_ ^ 0xff) * 0x100000001b3ULL;
    return true;
  }
  std::string hex() const {
    char s[17];
    std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(h_));
    return s;
  }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

}  // namespace vines::host
