// The split contact step's overlap equation (split/forced_contact.hpp) in
// the units of a contact (fixed/contact.hpp: overlap D, speed V, time
// T = D / V, force m V^2 / D, m the particle's mass), where every one of its
// quantities is O(1) and fits Q3.28, with the moments' lever arm in a unit
// tau of its own (the sensor step: (h - t) / tau stays in [0, 1]):
//   q       D^{1/4}                 u       V
//   t, h    T                       mu_k    m V tau^k
//   e       m V^2                   w       T / D^{3/4}  (dt = 4 q^3 dw)
//   1 / m*  1 / m                   M_{k+2} 1 / (m T tau^k)
//   G_k     V / T        (g(t)'s Taylor coefficients in powers of t / tau)
// The conversions run in double, where the coupling is built (the Markov
// parameters are the model's constants); docs/fixed_point.md has the
// formats and their ranges.
#pragma once

#include <cmath>

#include "vines/fixed/contact.hpp"
#include "vines/split/forced_contact.hpp"

namespace vines::fixed {

struct CouplingUnits {
  ContactUnits u;
  double tau = 0;  // the moments' time unit [s]
};

// The coupling c (SI) in the units cu, in the scalar S (r_scale in R).
template <typename S, typename R = S, int K>
ContactCoupling<S, K, R> scaled_coupling(const ContactCoupling<double, K>& c, const CouplingUnits& cu) {
  const ContactUnits& u = cu.u;
  ContactCoupling<S, K, R> out;
  out.inv_m_star = S(c.inv_m_star * u.m);
  double arm = 1.0;  // tau^k
  for (int k = 0; k < K; ++k, arm *= cu.tau) out.markov[k] = S(c.markov[k] * u.m * u.t * arm);
  double tk = u.t / u.v;  // tau^k T / V (c's g in powers of seconds)
  for (int k = 0; k < 4; ++k, tk *= cu.tau) out.g[k] = S(c.g[k] * tk);
  out.h = S(c.h / u.t);
  out.r_scale = R(u.t / cu.tau);
  return out;
}

// A state [q, u, t, mu_0..mu_{K-1}, e] from SI to the units cu (to = true)
// or back.
template <int R>
Eigen::Matrix<double, R, 1> convert_state(const Eigen::Matrix<double, R, 1>& y, const CouplingUnits& cu, bool to) {
  constexpr int K = R - 4;
  const ContactUnits& u = cu.u;
  Eigen::Matrix<double, R, 1> unit;
  unit(0) = std::sqrt(std::sqrt(u.d));
  unit(1) = u.v;
  unit(2) = u.t;
  double arm = u.m * u.v;
  for (int k = 0; k < K; ++k, arm *= cu.tau) unit(3 + k) = arm;
  unit(K + 3) = u.m * u.v * u.v;
  return to ? Eigen::Matrix<double, R, 1>(y.cwiseQuotient(unit)) : Eigen::Matrix<double, R, 1>(y.cwiseProduct(unit));
}

}  // namespace vines::fixed
