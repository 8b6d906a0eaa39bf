// The split contact step's Runge-Kutta step in w (substep_split.hpp,
// split/forced_contact.hpp), in any consistent units and any scalar: for a
// contact at q with overlap rate u under a free relative acceleration toward
// the wall of at most g. The contact's energy (1/2) m* u^2 + (2/5) c q^10
// (its Hertz part, c the law's elastic coefficient) reaches
// q^10 + (5/4) (m*/c) u^2 at rest; g pressing from rest reaches
// q^6 = (5/2) m* g / c; the contact's scale q_e is the larger (and at least
// q itself, which the energy's root is but for q^10 underflowing a fixed
// format, and q_floor), and with the speed of an impact that deep,
// v_e = sqrt(0.8 c / m*) q_e^5, dw = q_e / (n v_e) = dw_unit / q_e^4,
// dw_unit = 1 / (n sqrt(0.8 c / m*)): the contact's own oscillation then
// turns about 5.5 / n radians a step. dw is at most dw_max (a fixed-point
// format's bound; infinity in floating point).
//
// The fractional powers: std::pow in floating point, numeric::power
// (integer base-2 logarithm and exponential, relative error below 2^-9) in
// fixed point: a step size, not a result, so the same bits on every core
// matter more than the last digit.
#pragma once

#include <cmath>

#include "vines/numeric/fixed_math.hpp"
#include "vines/numeric/minmax.hpp"

namespace vines::fixed {

// x^(a/b) in floating point; a Fixed finds numeric::power by its namespace
// (the more specialised overload).
template <typename S>
S power(S x, int a, int b) {
  return std::pow(x, S(a) / S(b));
}

template <typename S>
struct ContactStep {
  S dw, q_e;
};

// The step of a contact of depth scale q_e.
template <typename S>
ContactStep<S> step_of_scale(S q_e, S dw_unit, S dw_max) {
  const S q_e2 = q_e * q_e;
  const S q_e4 = numeric::max_of(q_e2 * q_e2, dw_unit / dw_max);
  return {dw_unit / q_e4, q_e};
}

// m_star_c = m* / c; g >= 0.
template <typename S>
ContactStep<S> contact_step(S q, S u, S g, S m_star_c, S q_floor, S dw_unit, S dw_max) {
  const S q2 = q * q, q10 = q2 * q2 * q2 * q2 * q2;
  const S by_energy = power(q10 + S(1.25) * m_star_c * u * u, 1, 10);
  const S by_force = power(S(2.5) * m_star_c * g, 1, 6);
  const S q_e = numeric::max_of(numeric::max_of(by_energy, by_force), numeric::max_of(q, q_floor));
  return step_of_scale(q_e, dw_unit, dw_max);
}

}  // namespace vines::fixed
