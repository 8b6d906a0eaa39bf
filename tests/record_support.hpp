// Shared by the record tests (test_record.cpp, test_resample.cpp): a record
// spec for a path, the ground-motion folder this build reads.
#pragma once

#include <string>

#include "host/record.hpp"

namespace vines::record_test {

inline hal::RecordSpec spec_for(const std::string& path, hal::RecordFormat format = hal::RecordFormat::kAuto) {
  hal::RecordSpec s;
  s.path = path;
  s.format = format;
  return s;
}

inline std::string motions_dir() {
#ifdef VINES_DEFAULT_GROUND_MOTIONS
  return VINES_DEFAULT_GROUND_MOTIONS;
#else
  return "";
#endif
}

}  // namespace vines::record_test
