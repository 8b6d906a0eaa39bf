// Helpers of the tests that hold a run against a stored converged reference
// (data/reference/NAME.json, written by `vines reference`).
#pragma once

#include <cmath>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace vines::test {

// |a - b| / |b|.
inline double rel(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

inline nlohmann::json reference(const std::string& name) {
  std::ifstream in(std::string(VINES_SOURCE_DIR) + "/data/reference/" + name + ".json");
  return nlohmann::json::parse(in);
}

}  // namespace vines::test
