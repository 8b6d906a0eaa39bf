// The overlap's equation in a contact on the frame, over one sensor step
// (issue 34's split step, docs/fixed_point.md). A force F on the device floor
// accelerates that floor by F / m_f at once (every mode kept: Phi Phi^T =
// M^-1) and the ground acceleration cancels from the overlap d, so
//   d'' = -F(d, d') / m* + g(t) + k_f y + c_f y',
//   y'' = F / m_f - k_f y - c_f y',
// with g(t) = g0 + g1 t + g2 t^2/2 + g3 t^3/6 the floor's free spring-and-
// damper acceleration toward the wall over the step (a Taylor cubic from the
// state at the step's start), y the floor's displacement by this step's
// contact force, and k_f = K_ff / m_f, c_f = C_ff / m_f its own stiffness
// and damping (the neighbours' share, of relative order (omega h)^2, is
// left out). Integrated in w (dt/dw = 4 q^3, q = d^{1/4}) by classic
// Runge-Kutta, with the force's moments about the step's end,
// mu_k = int F(s) (h - s)^k / k! ds (k = 0..3), which move the frame
// (fixed/force_moments.hpp) and the particle, and the energy lost.
#pragma once

#include <Eigen/Core>

#include "vines/contact.hpp"
#include "vines/numeric/rk4.hpp"

namespace vines::fixed {

template <typename S>
struct ContactCoupling {
  S inv_m_star = S(0), inv_m_floor = S(0);  // 1 / m*, 1 / m_f
  S k_floor = S(0), c_floor = S(0);         // K_ff / m_f, C_ff / m_f
  S g[4] = {S(0), S(0), S(0), S(0)};        // g(t)'s Taylor coefficients
  S h = S(0);                               // the step's end
};

// [q, u, t, y, y', mu_0..mu_3, e]: u = d', t from the step's start.
template <typename S>
using ContactState = Eigen::Matrix<S, 10, 1>;

template <typename S>
struct ForcedContact {
  ContactState<S> y;
  bool ended = false;  // the contact ended (q back to 0) before the step's end
  int steps = 0;
};

namespace detail {

template <typename S, typename K>
ContactState<S> contact_rate(const K& law, const ContactCoupling<S>& c, const ContactState<S>& y) {
  const S q = y(0), u = y(1), t = y(2), j = S(4) * q * q * q;
  const contact::Force<S> f = law.regular(q, u);
  const S force = f.total(), r = c.h - t;
  const S g = c.g[0] + t * (c.g[1] + t * (c.g[2] / S(2) + t * c.g[3] / S(6)));
  const S spring = c.k_floor * y(3) + c.c_floor * y(4);
  const S jf = j * force;
  ContactState<S> d;
  d << u, j * (g + spring - force * c.inv_m_star), j, j * y(4), j * (force * c.inv_m_floor - spring), jf, jf * r,
      jf * r * r / S(2), jf * r * r * r / S(6), j * f.dissipative * u;
  return d;
}

}  // namespace detail

// From y0 (q > 0, or q = 0 with u > 0 at first touch) to the contact's end
// or the step's end, whichever comes first, `dw` in w a step, at most
// max_steps; each end placed by Newton steps on a re-taken last step.
template <typename S, typename K>
ForcedContact<S> forced_contact(const K& law, const ContactCoupling<S>& c, const ContactState<S>& y0, S dw,
                                int max_steps) {
  auto rate = [&](const ContactState<S>& y) { return detail::contact_rate(law, c, y); };
  ForcedContact<S> out;
  out.y = y0;
  for (; out.steps < max_steps; ++out.steps) {
    const ContactState<S> next = numeric::rk4_step(rate, out.y, dw);
    const bool ends = next(0) < S(0), late = next(2) > c.h;
    if (!ends && !late) {
      out.y = next;
      continue;
    }
    // Which comes first: the secant guesses of both, the earlier kept.
    S theta_end = ends ? out.y(0) / (out.y(0) - next(0)) : S(2);
    S theta_h = late ? (c.h - out.y(2)) / (next(2) - out.y(2)) : S(2);
    const bool contact_ends = theta_end < theta_h;
    S theta = contact_ends ? theta_end : theta_h;
    ContactState<S> y = numeric::rk4_step(rate, out.y, theta * dw);
    for (int it = 0; it < 3; ++it) {
      const ContactState<S> d = rate(y);  // d/dw at the guess
      const S miss = contact_ends ? y(0) : y(2) - c.h, slope = contact_ends ? d(0) : d(2);
      if (slope == S(0)) break;
      theta = theta - miss / (slope * dw);
      y = numeric::rk4_step(rate, out.y, theta * dw);
    }
    out.y = y;
    out.ended = contact_ends;
    ++out.steps;
    return out;
  }
  return out;
}

}  // namespace vines::fixed
