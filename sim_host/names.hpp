// Names of the model's choices as scene files and outputs spell them.
#pragma once

#include "vines/params.hpp"

namespace vines::host {

inline const char* device_name(DeviceKind k) {
  switch (k) {
    case DeviceKind::kTmd: return "tmd";
    case DeviceKind::kVines: return "vines";
    default: return "none";
  }
}

inline const char* law_name(ContactLaw l) {
  switch (l) {
    case ContactLaw::kHertz: return "hertz";
    case ContactLaw::kTsuji: return "tsuji";
    case ContactLaw::kKuwabara: return "kuwabara";
    default: return "restitution";
  }
}

}  // namespace vines::host
