// The scalar type a scene runs the firmware loop in: double, float, or Q3.28
// fixed point (the fixed-point engine, fixed/frame.hpp and fixed/vines_step.hpp).
#pragma once

namespace vines::host {

enum class Scalar { kDouble, kFloat, kFixed };

inline const char* scalar_name(Scalar s) {
  return s == Scalar::kFloat ? "float" : s == Scalar::kFixed ? "fixed" : "double";
}

}  // namespace vines::host
