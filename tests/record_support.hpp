// Shared by the record tests (test_record*.cpp, test_resample.cpp): a record
// spec for a path, the ground-motion folder this build reads, a fresh folder
// for hand-written files, and the refusal of a spec.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
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

// A fresh directory per test for hand-written record files.
class RecordFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("vines_record_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Writes bytes exactly as given (CRLF stays CRLF) and returns the path.
  std::string write(const std::string& name, const std::string& bytes) {
    const std::filesystem::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }

  std::filesystem::path dir_;
};

// The RecordError message load_record throws for spec ("" and a test failure if none).
inline std::string error_of(const hal::RecordSpec& spec) {
  try {
    hal::load_record(spec);
  } catch (const hal::RecordError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no RecordError for " << spec.path;
  return "";
}

}  // namespace vines::record_test
