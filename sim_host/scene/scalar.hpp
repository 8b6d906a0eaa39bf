// The scalar type a scene runs the firmware loop in: double, float, or Q3.28
// fixed point (the fixed-point engine, fixed/frame.hpp and fixed/vines_step.hpp).
#pragma once

namespace vines::host {

enum class Scalar { kDouble, kFloat, kFixed };

// The link's code of a scalar (link::NodeConfig::scalar) and back; a code
// past the last is read as double (decode() refuses it first).
inline unsigned char link_code(Scalar s) { return static_cast<unsigned char>(s); }
inline Scalar scalar_of_code(unsigned char c) { return c <= 2 ? static_cast<Scalar>(c) : Scalar::kDouble; }

inline const char* scalar_name(Scalar s) {
  return s == Scalar::kFloat ? "float" : s == Scalar::kFixed ? "fixed" : "double";
}

}  // namespace vines::host
