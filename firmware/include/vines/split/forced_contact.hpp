// The overlap's equation in a contact on the frame, over one sensor step
// (issue 34's split step, docs/fixed_point.md). The ground acceleration
// cancels from the overlap d; the particle takes -F / m, and the device
// floor its free motion plus its response to the force, which the frame's
// Markov parameters M_n give (the floor's impulse response is
// sum_n M_n tau^n / n!): with I_k(t) = int_0^t F(s) (t - s)^k / k! ds,
//   d'' = g(t) - F / m - M_1 F - M_2 I_0 - ... - M_{K+1} I_{K-1},
// g(t) the free relative acceleration toward the wall over the step, a
// Taylor cubic from the state at the step's start, in powers of the
// moments' time unit (x = t r_scale): g = G0 + G1 x + G2 x^2 + G3 x^3,
// G_k = g^(k) tau^k / k! (in fixed point, where tau is the sensor step,
// every G_k is then of the size of the acceleration's change over the
// step, whatever the contact's own time unit). Integrated in w (dt/dw = 4 q^3, q = d^{1/4}) by classic
// Runge-Kutta, with the energy lost and the force's moments about the
// step's end, mu_k = int F(s) (h - s)^k / k! ds (k < K), which move the
// frame (split/force_moments.hpp) and the particle, and from which the I_k
// follow (floor_response). Each moment's rate is a quadrature of the force,
// not a chain of integrals of one another: Runge-Kutta's error is then that
// of the contact's own path.
//
// Units: any consistent set (SI in the double and float loops). In fixed
// point the contact's own (fixed/contact.hpp: overlap D, speed V, time
// T = D / V, force m V^2 / D), with the moments' lever arm (h - s) in a unit
// tau of its own (the sensor step, so that it stays within [0, 1] at every
// rate): r_scale = T / tau, mu_k in m V tau^k, M_{k+2} in 1 / (m T tau^k)
// (fixed/contact_coupling.hpp).
#pragma once

#include <cmath>
#include <type_traits>

#include <Eigen/Core>

#include "vines/model/contact.hpp"
#include "vines/numeric/rk4.hpp"

namespace vines::fixed {

// K: the moments carried (the frame's response to the force is then exact
// to the power K - 1 of the step in the positions, K in the velocities,
// split/force_moments.hpp).
// R: the type of r_scale (S; in fixed point a numeric::Gain, since T / tau
// may pass the format's range).
template <typename S, int K = 4, typename R = S>
struct ContactCoupling {
  S inv_m_star = S(0);  // 1 / m + M_1 (M_1 = 1 / m_f, the floor's mass)
  S markov[K] = {};     // M_2 .. M_{K+1}
  S g[4] = {};          // g(t)'s Taylor coefficients in powers of t r_scale (G_k above)
  S h = S(0);           // the step's end
  R r_scale = R(1);     // the moments' lever arm (h - t) in its own unit: (h - t) r_scale
};

// [q, u, t, mu_0..mu_{K-1}, e]: u = d', t from the step's start.
template <typename S, int K = 4>
using ContactState = Eigen::Matrix<S, K + 4, 1>;

template <typename S, int K = 4>
struct ForcedContact {
  ContactState<S, K> y;
  bool ended = false;   // the contact ended (q back to 0) before the step's end
  bool capped = false;  // max_steps taken short of both ends
  int steps = 0;
  S q_max = S(0);       // the largest q at the steps' ends (the contact's depth)
};

namespace detail {

// x / j: Fixed's one 32-bit division (numeric/fixed.hpp), a floating
// point's own; none for j = 1 (the series' first terms).
template <typename S>
S over(S x, int j) {
  if (j == 1) return x;
  if constexpr (std::is_floating_point_v<S>)
    return x / static_cast<S>(j);
  else
    return x / j;
}

// The floor's response term sum_k M_{k+2} I_k(t), from the moments about
// the step's end (I_k(t) = sum_{i <= k} mu_i (t - h)^{k-i} / (k-i)!),
// gathered per moment: sum_i mu_i sum_{j < K - i} M_{i+j+2} x^j / j!,
// x = (t - h) r_scale = -r.
template <typename S, int K, typename R>
S floor_response(const ContactCoupling<S, K, R>& c, const ContactState<S, K>& y, S r) {
  const S x = -r;
  S sum = S(0);
  for (int i = 0; i < K; ++i) {
    S poly = c.markov[K - 1];
    for (int j = K - 1 - i; j > 0; --j) poly = c.markov[i + j - 1] + over(x * poly, j);
    sum += poly * y(3 + i);
  }
  return sum;
}

// The rates d/dw times `scale` (1: the rates; a step dw: its increments,
// folded into dt/dw, one product); span = h r_scale (the lever arm at t = 0).
template <typename S, int K, typename R, typename Law>
ContactState<S, K> contact_rate(const Law& law, const ContactCoupling<S, K, R>& c, const ContactState<S, K>& y,
                                S span, S scale = S(1)) {
  const S q = y(0), u = y(1), t = y(2), j = S(4) * q * q * q * scale;
  const contact::Force<S> f = law.regular(q, u);
  const S force = f.total();
  const S x = t * c.r_scale, r = span - x;  // t and h - t in the lever arm's unit
  const S g = c.g[0] + x * (c.g[1] + x * (c.g[2] + x * c.g[3]));
  ContactState<S, K> d;
  d(0) = u * scale;
  d(1) = j * (g - floor_response(c, y, r) - force * c.inv_m_star);
  d(2) = j;
  // mu_k' = F (h - t)^k / k!, each term from the last (none past the last:
  // in fixed point a product and a division of every rate).
  S term = j * force;
  for (int k = 0; k < K; ++k) {
    d(3 + k) = term;
    if (k + 1 < K) term = over(term * r, k + 1);
  }
  d(K + 3) = j * f.dissipative * u;
  return d;
}

}  // namespace detail

// A bound on |g(t)| over the step: sum_k |G_k| (h r_scale)^k.
template <typename S, int K, typename R>
S g_bound(const ContactCoupling<S, K, R>& c) {
  using std::abs;
  const S span = c.h * c.r_scale;
  return abs(c.g[0]) + span * (abs(c.g[1]) + span * (abs(c.g[2]) + span * abs(c.g[3])));
}

// Near a contact's ends (q small against its scale q_ref) the path is
// nearly q = q0 + u w and the force's terms are tiny: a step there may be
// up to this many times dw (dw q_ref / (2 q)).
inline constexpr int kMaxStretch = 4;

// Newton steps placing a step's end on the contact's end or the sensor
// step's end, after the secant guess: three in floating point; in fixed
// point one (after it, theta moves by at most a few of Q3.28's units, while
// each further step re-takes a Runge-Kutta step: on a Cortex-M3 the worst
// sensor step's largest part).
template <typename S>
inline constexpr int kNewtonSteps = std::is_floating_point_v<S> ? 3 : 1;

// From y0 (q > 0, or q = 0 with u > 0 at first touch) to the contact's end
// or the step's end, whichever comes first, in steps of dw in w (stretched
// near the contact's ends by q_ref, see kMaxStretch; q_ref = 0: none), at
// most max_steps; each end placed by Newton steps on a re-taken last step.
template <typename S, int K, typename R, typename Law>
ForcedContact<S, K> forced_contact(const Law& law, const ContactCoupling<S, K, R>& c, const ContactState<S, K>& y0,
                                   S dw, S q_ref, int max_steps) {
  using State = ContactState<S, K>;
  const S span = c.h * c.r_scale;
  auto rate = [&](const State& y) { return detail::contact_rate(law, c, y, span); };
  // Classic Runge-Kutta; in fixed point on the rates' increments (no
  // weight products: the stages halve, the sum divides by 6 once).
  auto advance = [&](const State& y, S h) {
    if constexpr (std::is_floating_point_v<S>)
      return numeric::rk4_step(rate, y, h);
    else
      return numeric::rk4_increments([&](const State& v) { return detail::contact_rate(law, c, v, span, h); }, y);
  };
  const S reach = q_ref / 2, most = S(kMaxStretch) * dw;
  ForcedContact<S, K> out;
  out.y = y0;
  out.q_max = y0(0);
  for (; out.steps < max_steps; ++out.steps) {
    const S q = out.y(0);
    const S step = q >= reach ? dw : (q * S(kMaxStretch) <= reach ? most : dw * reach / q);
    const State next = advance(out.y, step);
    const bool ends = next(0) < S(0), late = next(2) > c.h;
    if (!ends && !late) {
      out.y = next;
      if (next(0) > out.q_max) out.q_max = next(0);
      continue;
    }
    // Which comes first: the secant guesses of both, the earlier kept.
    S theta_end = ends ? out.y(0) / (out.y(0) - next(0)) : S(2);
    S theta_h = late ? (c.h - out.y(2)) / (next(2) - out.y(2)) : S(2);
    const bool contact_ends = theta_end < theta_h;
    S theta = contact_ends ? theta_end : theta_h;
    State y = advance(out.y, theta * step);
    for (int it = 0; it < kNewtonSteps<S>; ++it) {
      const State d = rate(y);  // d/dw at the guess
      const S miss = contact_ends ? y(0) : y(2) - c.h, slope = contact_ends ? d(0) : d(2);
      if (slope == S(0)) break;
      S next_theta = theta - miss / (slope * step);
      next_theta = next_theta < S(0) ? S(0) : (next_theta > S(1) ? S(1) : next_theta);  // the end lies in this step
      if (next_theta == theta) break;  // converged: the step would be the same
      theta = next_theta;
      y = advance(out.y, theta * step);
    }
    out.y = y;
    if (y(0) > out.q_max) out.q_max = y(0);
    out.ended = contact_ends;
    ++out.steps;
    return out;
  }
  out.capped = true;
  return out;
}

}  // namespace vines::fixed
