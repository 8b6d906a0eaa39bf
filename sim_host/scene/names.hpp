// Names of the model's choices as scene files and outputs spell them (a
// contact law's: law_name, vines/model/contact_laws.hpp).
#pragma once

#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "host/record.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/params.hpp"

namespace vines::host {

inline const char* device_name(DeviceKind k) {
  switch (k) {
    case DeviceKind::kTmd: return "tmd";
    case DeviceKind::kVines: return "vines";
    default: return "none";
  }
}

// A record's format and units as the scene's [record] spells them (also
// --record-format, --record-units and the Python package's Record.load).
template <class E>
using NamedValues = std::vector<std::pair<std::string_view, E>>;
inline const NamedValues<hal::RecordFormat> kRecordFormats = {{"auto", hal::RecordFormat::kAuto},
                                                              {"at2", hal::RecordFormat::kAt2},
                                                              {"time-accel", hal::RecordFormat::kTimeAccel},
                                                              {"accel", hal::RecordFormat::kAccel}};
inline const NamedValues<hal::Units> kRecordUnits = {
    {"g", hal::Units::kG}, {"m/s2", hal::Units::kMps2}, {"cm/s2", hal::Units::kCmps2}};

// The value named `name` in `values`, if any.
template <class E>
std::optional<E> named(const NamedValues<E>& values, std::string_view name) {
  for (const auto& [n, v] : values)
    if (n == name) return v;
  return std::nullopt;
}

}  // namespace vines::host
