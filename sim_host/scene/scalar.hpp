// The scalar type a scene runs the firmware loop in.
#pragma once

namespace vines::host {

enum class Scalar { kDouble, kFloat };

inline const char* scalar_name(Scalar s) { return s == Scalar::kFloat ? "float" : "double"; }

}  // namespace vines::host
