// The record reader's errors, "path:line: what" or "path: what", and its
// number format (record.cpp, resample.cpp). Internal to hal/host.
#pragma once

#include <cstddef>
#include <sstream>
#include <string>

#include "host/record.hpp"

namespace vines::hal::detail {

[[noreturn]] inline void fail(const std::string& path, const std::string& what) {
  throw RecordError(path + ": " + what);
}

[[noreturn]] inline void fail(const std::string& path, std::size_t line, const std::string& what) {
  throw RecordError(path + ":" + std::to_string(line) + ": " + what);
}

inline std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

}  // namespace vines::hal::detail
