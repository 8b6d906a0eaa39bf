// The exact step of a sensor period, the common case of the loop (sim.hpp):
// the linear part stepped exactly (modal form, readouts fused into the
// step), the free VI NES particle flown exactly, the checks that decide
// whether the step can be committed as it is (the particle clear of the
// walls, the frame within its limit), and the step integrals it commits
// (E_e, and the energy ledger and per-floor peaks when asked for). Plain
// steps (nothing but the common case) run in a tight loop (plain_steps);
// any other exact step in full (finish_exact). step() and run() share
// these, out of line, so that both compile one arithmetic.
#pragma once

#include <cmath>

#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/inline.hpp"
#include "vines/numeric/minmax.hpp"
#include "vines/step/peaks.hpp"
#include "vines/step/substep.hpp"

namespace vines {

namespace detail {

// Divergence check (MuJoCo-style warning) on a state z (with the particle at
// s, s'): anything non-finite, a floor or the TMD beyond the model's limit,
// or a particle beyond a wall by more than its radius. The floors are first
// bounded cheaply (bound: sum of |q_j| max_i |phi_ij|; vprobe: non-finite if
// any velocity coordinate is, see StepRead); only a bound beyond the limit
// costs the floors themselves. frame_diverged is the check without the
// particle: an exact step checks only that, its particle having passed
// may_touch (strictly between the walls, finite position and speed).
// frame_bounded is the cheap part alone, what a plain step needs: all finite
// (v - v is NaN for an infinite or NaN v), the bound and a TMD within the
// limit.
template <typename S, int N, typename Dev>
VINES_INLINE bool frame_bounded(const Model<S, N, Dev>& m, const typename Model<S, N, Dev>::VecX& z, S bound,
                                S vprobe) {
  const S limit = m.divergence_limit;
  if (!(bound + (vprobe - vprobe) <= limit)) return false;
  if constexpr (Dev::kKind == DeviceKind::kTmd) return std::fabs(z(N)) <= limit;
  return true;
}
template <typename S, int N, typename Dev>
VINES_INLINE bool frame_diverged(const Model<S, N, Dev>& m, const typename Model<S, N, Dev>::VecX& z, S bound,
                                 S vprobe) {
  if (VINES_LIKELY(frame_bounded(m, z, bound, vprobe))) return false;
  const S limit = m.divergence_limit;
  if (!std::isfinite(bound + vprobe)) return true;  // bound >= 0: an infinity stays one
  if (bound > limit && !(m.floor_x(z).cwiseAbs().maxCoeff() <= limit)) return true;
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    if (!(std::fabs(z(N)) <= limit)) return true;
  }
  return false;
}
template <typename S, int N, typename Dev>
bool diverged(const Model<S, N, Dev>& m, const typename Model<S, N, Dev>::VecX& z, S xf, S s, S sd) {
  if (frame_diverged(m, z, m.floor_bound(z), z.template tail<Model<S, N, Dev>::kP>().sum())) return true;
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    const S r = s - xf, radius = m.dev.radius;
    if (!(r >= m.dev.wall_left - radius && r <= m.dev.wall_right + radius) || !std::isfinite(sd)) return true;
  }
  return false;
}

// The exact step of the linear part from z0 to z1 with its readouts: the
// modal form fuses them into the step (step_read); the dense form (TMD)
// reads them off z1.
template <typename S, int N, typename Dev>
VINES_INLINE StepRead<S> linear_step(const Model<S, N, Dev>& m, const typename Model<S, N, Dev>::VecX& z0,
                                     typename Model<S, N, Dev>::VecX& z1, S a0, S a1) {
  if constexpr (Model<S, N, Dev>::kModal) {
    return step_read<Dev::kKind == DeviceKind::kVines, Layout<Dev, N>::kLanes>(m.lti, m.rows, z0, z1, a0, a1);
  } else {
    z1 = z0;
    m.lti.step(z1, a0, a1);
    StepRead<S> r;
    r.xt = m.top_x(z1);
    r.vt = m.top_v(z1);
    r.bound = m.floor_bound(z1);
    r.lin = S(0);
    r.xf = m.dev_x(z1);
    r.vf = m.dev_v(z1);
    r.vprobe = z1.template tail<Model<S, N, Dev>::kP>().sum();
    return r;
  }
}

// The exact steps of the linear part from z0 through the samples as[0..n]
// (as[0]: the sample at z0): zs[i], rs[i] after step i. One compiled loop
// that step() (n = 1) and run_exact() (a block) both call, out of line on
// purpose: inlined into each caller, the compiler would contract a * b + c
// into fma differently in each, and the loop image and the host would differ
// in the last bits.
template <typename S, int N, typename Dev>
VINES_NOINLINE void linear_steps(const Model<S, N, Dev>& m, const typename Model<S, N, Dev>::VecX& z0,
                                 typename Model<S, N, Dev>::VecX* zs, StepRead<S>* rs, const S* as, int n) {
  typename Model<S, N, Dev>::VecX z = z0, z1;
  for (int i = 0; i < n; ++i) {
    rs[i] = linear_step(m, z, z1, as[i], as[i + 1]);
    zs[i] = z1;
    z = z1;
  }
}

// E_e over the exact step from z (r: its readouts). With the Lyapunov
// split, a run of exact steps opens with V(z) added (E_e is then
// ee_sum - V(z_now)) and each step adds its linear form.
template <typename S, int N, typename Dev>
VINES_INLINE void add_elastic_step(const Model<S, N, Dev>& m, Carry<S>& d, const typename Model<S, N, Dev>::VecX& z,
                                   const StepRead<S>& r, S a0, S a1) {
  if (m.ee_lyapunov) {
    if (VINES_UNLIKELY(!d.ee_open)) {
      d.ee_sum.add(m.ee_boundary.eval(z, S(0)));
      d.ee_open = true;
    }
    d.ee_sum.add(r.lin);
  } else {
    d.ee_sum.add(m.strain_step.eval(z, a0, a1));
  }
}

// Closes a run of exact steps (before anything else changes the state).
template <typename S, int N, typename Dev>
void close_elastic_run(const Model<S, N, Dev>& m, Data<S, N, Dev>& d) {
  if (!d.ee_open) return;
  d.ee_sum.sub(m.ee_boundary.eval(d.z, S(0)));
  d.ee_open = false;
}

// The particle (at r, r' relative to the device floor at both ends of a
// free step) stays clear of both walls whatever its path in between, by
// more than the event tolerance: |r - r0| <= h max|r'|, and r' is bounded by
// its end values plus what a cubic through both ends allows between them.
template <typename S, int N, typename Dev>
VINES_INLINE bool clear_of_walls(const Model<S, N, Dev>& m, S r0, S rd0, S r1, S rd1) {
  const auto& dm = m.dev;
  const S reach = m.period * (numeric::max_of(std::fabs(rd0), std::fabs(rd1)) + std::fabs(rd1 - rd0)) + dm.round_tol;
  const S lo = numeric::min_of(r0, r1) - reach, hi = numeric::max_of(r0, r1) + reach;
  return lo > dm.clear_lo && hi < dm.clear_hi;
}

// The particle may touch a wall within the step: its overlap with a wall may
// exceed the event tolerance, where the sub-stepper would start a contact
// (cubic through both ends of the free step, with a margin for what a cubic
// misses and for rounding). A particle resting against a wall is not touching.
template <typename S, int N, typename Dev>
VINES_INLINE bool may_touch(const Model<S, N, Dev>& m, S r0, S rd0, S r1, S rd1) {
  const auto& dm = m.dev;
  const S h = m.period;
  if (VINES_LIKELY(clear_of_walls(m, r0, rd0, r1, rd1))) return false;
  const S margin = S(0.25) * h * std::fabs(rd1 - rd0) + dm.round_tol;
  const auto left = numeric::Cubic<S>::make(dm.wall_left - r0, -rd0, dm.wall_left - r1, -rd1, h);
  const auto right = numeric::Cubic<S>::make(r0 - dm.wall_right, rd0, r1 - dm.wall_right, rd1, h);
  return left.max_value() + margin > dm.event_tol || right.max_value() + margin > dm.event_tol;
}

// The clock and what is read at every sample, after a step (top floor now
// at velocity vt).
template <typename S>
VINES_INLINE void end_step(Carry<S>& d, S vt) {
  if (std::fabs(vt) > d.peak_top_velocity) d.peak_top_velocity = std::fabs(vt);
  ++d.k;
}

// Plain exact steps (readouts rs[i], samples as[i], as[i + 1], frame after
// them zs[i]) taken one after another while each needs nothing but the
// common case: the particle clear of the walls, the frame within its limit,
// E_e by the open Lyapunov split, the top floor below its running peak.
// Commits them to c (the frame is the caller's) and returns how many; the
// step it stops at goes to finish_exact(). A loop without calls, so that
// what it carries stays in registers; out of line and shared by step() and
// run_exact(), so that both compile one arithmetic (see linear_steps).
template <typename S, int N, typename Dev>
VINES_NOINLINE int plain_steps(const Model<S, N, Dev>& m, Carry<S>& c, const typename Model<S, N, Dev>::VecX* zs,
                               const StepRead<S>* rs, const S* as, int n) {
  if (!m.ee_lyapunov || !c.ee_open) return 0;
  const S h = m.period, peak = c.peak_top;
  // What a step hands the next: the particle (s, s') and relative to the
  // floor (r, r'), the top floor's |x| and |v|. Two sets, a step reading one
  // and writing the other, so that the loop needs no register moves.
  struct Hand {
    S s, sd, r, rd, ax, av;
  };
  S vpeak = c.peak_top_velocity;
  numeric::Sum<S> ee = c.ee_sum;
  // Step i from a to b; false (b untouched) if step i is not plain.
  auto advance = [&](const Hand& a, Hand& b, int i) {
    const StepRead<S>& r = rs[i];
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      free_flight(m, a.s, a.sd, as[i], as[i + 1], &b.s, &b.sd);
      b.r = b.s - r.xf;
      b.rd = b.sd - r.vf;
      if (!clear_of_walls(m, a.r, a.rd, b.r, b.rd)) return false;
    }
    if (!frame_bounded(m, zs[i], r.bound, r.vprobe)) return false;
    b.ax = std::fabs(r.xt);
    b.av = std::fabs(r.vt);
    if (abs_bound(a.ax, a.av, b.ax, b.av, h) > peak) return false;
    ee.add(r.lin);
    vpeak = numeric::max_of(vpeak, b.av);
    return true;
  };
  Hand x{c.s, c.sd, c.s - c.xf, c.sd - c.vf, std::fabs(c.xt), std::fabs(c.vt)}, y = x;
  int i = 0;
  while (i < n && advance(x, y, i) && ++i < n && advance(y, x, i)) ++i;
  const Hand& last = i % 2 ? y : x;
  if (i > 0) {
    c.xt = rs[i - 1].xt;
    c.vt = rs[i - 1].vt;
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      c.s = last.s;
      c.sd = last.sd;
      c.xf = rs[i - 1].xf;
      c.vf = rs[i - 1].vf;
    }
    c.peak_top_velocity = vpeak;
    c.ee_sum = ee;
    c.k += i;
  }
  return i;
}

// What became of an exact step.
enum class Exact : unsigned char { kDone, kCareful, kDiverged };

// Finishes the exact step of the linear part from z0 to z1 (readouts r),
// from a0 to a1, in full: the particle flies, and the step is committed to c
// with its step integrals (kDone; the caller commits z1 and ends the step),
// unless the VI NES particle may touch a wall during it (kCareful) or the
// frame diverged (kDiverged), which change nothing. Out of line, shared by
// step() and run_exact() (see plain_steps).
template <typename S, int N, typename Dev>
VINES_NOINLINE Exact finish_exact(const Model<S, N, Dev>& m, Carry<S>& c, const typename Model<S, N, Dev>::VecX& z0,
                                  const typename Model<S, N, Dev>::VecX& z1, const StepRead<S>& r, S a0, S a1) {
  S s1 = S(0), sd1 = S(0);  // the particle (VI NES)
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    free_flight(m, c.s, c.sd, a0, a1, &s1, &sd1);
    if (may_touch(m, c.s - c.xf, c.sd - c.vf, s1 - r.xf, sd1 - r.vf)) return Exact::kCareful;
  }
  if (VINES_UNLIKELY(frame_diverged(m, z1, r.bound, r.vprobe))) return Exact::kDiverged;
  add_elastic_step(m, c, z0, r, a0, a1);
  const S peak = top_peak_of_step(m, z0, z1, a0, a1, c.xt, c.vt, r.xt, r.vt, c.peak_top);
  if (VINES_UNLIKELY(peak > c.peak_top)) {
    c.peak_top = peak;
    c.peak_top_k = c.k;
    c.peak_top_dt = m.period;
  }
  c.xt = r.xt;
  c.vt = r.vt;
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    c.s = s1;
    c.sd = sd1;
    c.xf = r.xf;
    c.vf = r.vf;
  }
  return Exact::kDone;
}

// What an exact step from d.z to z1 keeps when asked: the energy ledger
// (sd0: the particle's speed before the step) and per-floor peaks.
template <typename S, int N, typename Dev>
void keep_extras(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, const typename Model<S, N, Dev>::VecX& z1, S a0,
                 S a1, S sd0) {
  if (m.loop.energy_ledger) {
    d.ledger.input.add(m.input_step.eval(d.z, a0, a1));
    d.ledger.damping.add(m.damping_step.eval(d.z, a0, a1));
    if constexpr (Dev::kKind == DeviceKind::kVines) d.ledger.input.sub(free_flight_work(m, sd0, a0, a1));
  }
  if (m.loop.floor_peaks)
    update_peaks<S, N>(m.floor_x(d.z), m.floor_v(d.z), m.floor_x(z1), m.floor_v(z1), m.period, d.peak_x, d.peak_drift);
}

}  // namespace detail

}  // namespace vines
