// Names of the model's choices as scene files and outputs spell them (a
// contact law's: law_name, vines/contact_laws.hpp).
#pragma once

#include "vines/contact_laws.hpp"
#include "vines/params.hpp"

namespace vines::host {

inline const char* device_name(DeviceKind k) {
  switch (k) {
    case DeviceKind::kTmd: return "tmd";
    case DeviceKind::kVines: return "vines";
    default: return "none";
  }
}

}  // namespace vines::host
