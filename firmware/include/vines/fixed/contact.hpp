// A contact law in fixed point: the law's own kernel (contact.hpp,
// regular(q, dd): a polynomial in q = d^{1/4} and the overlap rate dd, no
// roots), run on Fixed<F> with its coefficients in the units of a contact,
// where every quantity of an impact is O(1):
//   overlap  D = the deepest overlap of an elastic impact at speed V
//            (contact::hertz_max_overlap of the mass m the force moves)
//   speed    V, a representative impact speed (the law's v_ref)
//   time     T = D / V
//   force    m V^2 / D
// There q^ = q / D^{1/4} lies in [0, ~1] and dd^ = dd / V in [-1, 1] for an
// impact at V, and the elastic force of the elastic impact at V peaks at
// exactly 5/4: the force's error is an absolute error against its peak,
// the resolution of the format (2^-28 for Q3.28), whatever the law's 10
// decades of force between first touch and the deepest overlap.
//
// scaled_kernel() needs no law-specific code: each coefficient of a kernel
// multiplies one monomial of q and dd (true of every law of the registry),
// so its scale is the force it alone gives at q = D^{1/4}, dd = V, in units
// of m V^2 / D.
#pragma once

#include <cmath>

#include "vines/model/contact.hpp"
#include "vines/numeric/fixed.hpp"

namespace vines::fixed {

struct ContactUnits {
  double d = 0, v = 0, t = 0, m = 0;  // overlap [m], speed [m/s], time [s], mass [kg]
  double force() const { return m * v * v / d; }
};

inline ContactUnits contact_units(double m, double c, double v) {
  ContactUnits u;
  u.m = m;
  u.v = v;
  u.d = contact::hertz_max_overlap(m, c, v);
  u.t = u.d / v;
  return u;
}

// The kernel K<double> k in the units u, in the scalar S (a Fixed, or double
// to check the scaling itself).
template <typename S, template <typename> class K>
K<S> scaled_kernel(const K<double>& k, const ContactUnits& u) {
  constexpr int kMax = 8;
  double value[kMax] = {};
  int n = 0;
  const double q1 = std::sqrt(std::sqrt(u.d));
  K<double>::coefficients([&](auto member) {
    K<double> one{};
    one.*member = 1.0;
    value[n++] = k.*member * one.regular(q1, u.v).total() / u.force();
  });
  K<S> out{};
  n = 0;
  K<S>::coefficients([&](auto member) { out.*member = S(value[n++]); });
  return out;
}

}  // namespace vines::fixed
