// The answer of a parameter check (validate.hpp, the contact laws' own checks
// in contact_laws.hpp, build_model): ok, or the field at fault and why.
#pragma once

#include <cmath>

namespace vines {

struct ParamError {
  const char* field = nullptr;    // dotted scene key, e.g. "vines.beta"
  const char* message = nullptr;  // what is wrong, e.g. "must be > 1"
  int index = -1;                 // array element (0-based), -1 if none
  bool ok() const { return field == nullptr; }
};

namespace detail {
inline bool finite_positive(double x) { return std::isfinite(x) && x > 0.0; }
}  // namespace detail

}  // namespace vines
