// Contact laws between the sphere and a wall: small stateless kernels (in the
// spirit of LAMMPS pair granular). Each returns the repulsive force for an
// overlap d > 0 and overlap rate dd, split into its elastic and dissipative
// parts; the force is applied whenever d > 0, even when the dissipative part
// makes it tensile near the end of a contact (docs/model.md section 4.5).
#pragma once

#include <cmath>

namespace vines::contact {

inline constexpr double kPi = 3.14159265358979323846;

template <typename S>
struct Force {
  S elastic;      // C d^{3/2}: stored, returned on unloading
  S dissipative;  // rate term: its power dissipative * dd is lost
  S total() const { return elastic + dissipative; }
};

// Hertz stiffness prefactor C = (4/3) E* sqrt(R*) for a sphere of radius r on
// a flat wall: R* = r, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2.
inline double hertz_c(double e1, double nu1, double e2, double nu2, double radius) {
  const double e_star = 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2);
  return 4.0 / 3.0 * e_star * std::sqrt(radius);
}

// Hertz contact duration for an elastic impact at speed v (reduced mass m):
// t_c = 3.218 (m / C)^{2/5} v^{-1/5}.
inline double hertz_duration(double m, double c, double v) {
  return 3.218 * std::pow(m / c, 0.4) * std::pow(v, -0.2);
}

// Deepest overlap of an elastic impact at speed v: (5 m v^2 / (4 C))^{2/5}.
inline double hertz_max_overlap(double m, double c, double v) {
  return std::pow(5.0 * m * v * v / (4.0 * c), 0.4);
}

// Tsuji damping prefactor D(eps) = -sqrt(5) ln(eps) / sqrt(ln^2(eps) + pi^2).
inline double tsuji_d(double eps) {
  const double l = std::log(eps);
  return -std::sqrt(5.0) * l / std::sqrt(l * l + kPi * kPi);
}

// Each law also gives its force in terms of q = d^{1/4} (regular(q, dd)):
// a polynomial in q, what the loop integrates contacts in (substep.hpp), and
// the energy its elastic part stores at overlap d (potential(d)).
// coefficients(f) calls f with a pointer to each coefficient member, in
// order: the model image carries them (model_image_fields.hpp).

// Energy stored by the elastic part C d^{3/2} at overlap d: (2/5) C d^{5/2}.
template <typename S>
S hertz_potential(S c, S d) {
  using std::sqrt;
  return S(0.4) * c * d * d * sqrt(d);
}

// F = C d^{3/2}.
template <typename S>
struct Hertz {
  S c;
  Force<S> operator()(S d, S /*dd*/) const {
    using std::sqrt;
    return {c * d * sqrt(d), S(0)};
  }
  Force<S> regular(S q, S /*dd*/) const {
    const S q2 = q * q;
    return {c * q2 * q2 * q2, S(0)};
  }
  S potential(S d) const { return hertz_potential(c, d); }
  template <typename F>
  static constexpr void coefficients(F&& f) { f(&Hertz::c); }
};

// F = C d^{3/2} + D(eps) sqrt(C m*) d^{1/4} dd, with g = D sqrt(C m*).
template <typename S>
struct Tsuji {
  S c;
  S g;
  Force<S> operator()(S d, S dd) const {
    using std::sqrt;
    const S sd = sqrt(d);
    return {c * d * sd, g * sqrt(sd) * dd};
  }
  Force<S> regular(S q, S dd) const {
    const S q2 = q * q;
    return {c * q2 * q2 * q2, g * q * dd};
  }
  S potential(S d) const { return hertz_potential(c, d); }
  template <typename F>
  static constexpr void coefficients(F&& f) {
    f(&Tsuji::c);
    f(&Tsuji::g);
  }
};

// Kuwabara-Kono: F = C d^{3/2} + (3/2) C tau d^{1/2} dd, with g = 1.5 C tau.
template <typename S>
struct Kuwabara {
  S c;
  S g;
  Force<S> operator()(S d, S dd) const {
    using std::sqrt;
    const S sd = sqrt(d);
    return {c * d * sd, g * sd * dd};
  }
  Force<S> regular(S q, S dd) const {
    const S q2 = q * q;
    return {c * q2 * q2 * q2, g * q2 * dd};
  }
  S potential(S d) const { return hertz_potential(c, d); }
  template <typename F>
  static constexpr void coefficients(F&& f) {
    f(&Kuwabara::c);
    f(&Kuwabara::g);
  }
};

// Instantaneous impact (Newton's law, Eq. 4) between masses m1 and m2 whose
// approach speed is v > 0: the impulse that reverses it with restitution eps.
template <typename S>
S restitution_impulse(S m1, S m2, S v, S eps) {
  return (S(1) + eps) * m1 * m2 / (m1 + m2) * v;
}

}  // namespace vines::contact
