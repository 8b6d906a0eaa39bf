// The fixed-step loop: one step per sensor sample, the ground acceleration
// linear between two samples. Pipeline of a step:
//   1. exact step of the linear part and the free particle into temporaries,
//      with what the loop reads off it taken in the same pass (modal form);
//      a VI NES checks whether its particle may touch a wall during the step;
//   2. if not: the exact step is committed with its exact step integrals
//      (E_e; the energy ledger and per-floor peaks only when asked for);
//      E_e by the Lyapunov split, a linear form per step; a plain step
//      (nothing but the common case) in a tight loop, any other in full;
//      if so: adaptive Dormand-Prince sub-steps through the step, contact
//      starts and ends located to rounding, capped per step (cap hits are
//      counted); or, with loop.contact_scheme = kBounded, at most
//      loop.bounded_substeps aimed sub-steps (substep_bounded.hpp);
//   3. guards (non-finite input held, diverging steps rolled back), counters.
// Work per step is bounded; no heap, no exceptions. run() feeds a block of
// samples: the same steps, with runs of plain exact steps taken in blocks
// (the frame through the block, then the particle and the checks).
#pragma once

#include <cmath>
#include <cstddef>

#include "vines/data.hpp"
#include "vines/model.hpp"
#include "vines/numeric/inline.hpp"
#include "vines/numeric/minmax.hpp"
#include "vines/peaks.hpp"
#include "vines/substep.hpp"
#include "vines/substep_bounded.hpp"

namespace vines {

namespace detail {

// Stored energies now and the balance residual.
template <typename S, int N, typename Dev>
void close_ledger(const Model<S, N, Dev>& m, Data<S, N, Dev>& d) {
  Ledger& l = d.ledger;
  l.kinetic = static_cast<double>(m.kinetic.eval(d.z, S(0)));
  l.strain = static_cast<double>(m.strain.eval(d.z, S(0)));
  l.device = static_cast<double>(m.device_potential.eval(d.z, S(0)));
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    l.kinetic += 0.5 * static_cast<double>(m.dev.m * d.sd * d.sd);
    l.device += static_cast<double>(contact_energy(m, d));
  }
  const double dissipated = l.damping + l.contact;
  const double stored = l.kinetic + l.strain + l.device;
  l.residual = l.initial + l.input - stored - dissipated;
  l.max_abs_residual = std::fmax(l.max_abs_residual, std::fabs(l.residual));
  l.max_input = std::fmax(l.max_input, std::fmax(l.initial + l.input, stored + dissipated));
}

// The top floor and the device floor from the state.
template <typename S, int N, typename Dev>
void refresh_floors(const Model<S, N, Dev>& m, Data<S, N, Dev>& d) {
  d.xt = m.top_x(d.z);
  d.vt = m.top_v(d.z);
  d.xf = m.dev_x(d.z);
  d.vf = m.dev_v(d.z);
}

}  // namespace detail

// Puts the run at t = 0 with ground acceleration a0: initial conditions of
// the scene, everything else zero.
template <typename S, int N, typename Dev>
void init(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a0) {
  d = Data<S, N, Dev>{};
  d.z.setZero();
  d.a_prev = a0;
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    d.z(N) = m.dev.x0;
    d.z(2 * N + 1) = m.dev.v0;
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    d.s = S(0);
    d.sd = m.dev.v0;
  }
  detail::refresh_floors(m, d);
  d.peak_x = m.floor_x(d.z).cwiseAbs();
  d.peak_drift.setZero();
  d.peak_top = std::fabs(d.xt);
  d.peak_top_velocity = std::fabs(d.vt);
  d.substep = m.hs;
  if (m.loop.energy_ledger) {
    detail::close_ledger(m, d);  // the energy stored by the initial conditions
    d.ledger.initial = d.ledger.kinetic + d.ledger.strain + d.ledger.device;
    d.ledger.max_abs_residual = 0;
    detail::close_ledger(m, d);
  }
  d.last_strain = static_cast<double>(m.strain.eval(d.z, S(0)));
}

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
  const S limit = static_cast<S>(m.loop.divergence_limit_m);
  if (!(bound + (vprobe - vprobe) <= limit)) return false;
  if constexpr (Dev::kKind == DeviceKind::kTmd) return std::fabs(z(N)) <= limit;
  return true;
}
template <typename S, int N, typename Dev>
VINES_INLINE bool frame_diverged(const Model<S, N, Dev>& m, const typename Model<S, N, Dev>::VecX& z, S bound,
                                 S vprobe) {
  if (VINES_LIKELY(frame_bounded(m, z, bound, vprobe))) return false;
  const S limit = static_cast<S>(m.loop.divergence_limit_m);
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
    const S r = s - xf, radius = static_cast<S>(m.dev.design.radius);
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
      d.ee_sum += static_cast<double>(m.ee_boundary.eval(z, S(0)));
      d.ee_open = true;
    }
    d.ee_sum += static_cast<double>(r.lin);
  } else {
    d.ee_sum += static_cast<double>(m.strain_step.eval(z, a0, a1));
  }
}

// Closes a run of exact steps (before anything else changes the state).
template <typename S, int N, typename Dev>
void close_elastic_run(const Model<S, N, Dev>& m, Data<S, N, Dev>& d) {
  if (!d.ee_open) return;
  d.ee_sum -= static_cast<double>(m.ee_boundary.eval(d.z, S(0)));
  d.ee_open = false;
}

// The particle (at r, r' relative to the device floor at both ends of a
// free step) stays clear of both walls whatever its path in between, by
// more than the event tolerance: |r - r0| <= h max|r'|, and r' is bounded by
// its end values plus what a cubic through both ends allows between them.
template <typename S, int N, typename Dev>
VINES_INLINE bool clear_of_walls(const Model<S, N, Dev>& m, S r0, S rd0, S r1, S rd1) {
  const auto& dm = m.dev;
  const S reach = m.hs * (numeric::max_of(std::fabs(rd0), std::fabs(rd1)) + std::fabs(rd1 - rd0)) + dm.round_tol;
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
  const S h = m.hs;
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
  const S h = m.hs, peak = c.peak_top;
  // What a step hands the next: the particle (s, s') and relative to the
  // floor (r, r'), the top floor's |x| and |v|. Two sets, a step reading one
  // and writing the other, so that the loop needs no register moves.
  struct Hand {
    S s, sd, r, rd, ax, av;
  };
  S vpeak = c.peak_top_velocity;
  double ee = c.ee_sum;
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
    ee += static_cast<double>(r.lin);
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
    c.t_peak_top = static_cast<double>(c.k) * m.h + m.h;
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
    d.ledger.input += static_cast<double>(m.input_step.eval(d.z, a0, a1));
    d.ledger.damping += static_cast<double>(m.damping_step.eval(d.z, a0, a1));
    if constexpr (Dev::kKind == DeviceKind::kVines) d.ledger.input -= free_flight_work(m, sd0, a0, a1);
  }
  if (m.loop.floor_peaks)
    update_peaks<S, N>(m.floor_x(d.z), m.floor_v(d.z), m.floor_x(z1), m.floor_v(z1), m.hs, d.peak_x, d.peak_drift);
}

}  // namespace detail

// Advances the run by one sensor period to the next sample a1 [m/s^2].
// Guards: a non-finite sample is replaced by the last good one (hold) and
// counted; a step that diverges is rolled back to the state before it (the
// model holds its last good state, the clock advances) and counted. Both
// counters are outputs; neither stops the loop.
template <typename S, int N, typename Dev>
VINES_INLINE void step(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a1) {
  using VecX = typename Model<S, N, Dev>::VecX;
  if (!std::isfinite(a1)) {
    ++d.count.bad_samples;
    a1 = d.a_prev;
  }
  const S a0 = d.a_prev;

  // 1.-2a. Exact step, committed unless it needs care or diverged: a plain
  // step if it can be, else in full.
  bool careful = false, plain = false;
  if constexpr (Dev::kKind == DeviceKind::kVines) careful = d.mode != Mode::kFree;
  if (!careful) {
    VecX z1;
    StepRead<S> r;
    const S as[2] = {a0, a1};
    detail::linear_steps(m, d.z, &z1, &r, as, 1);
    const bool extras = m.loop.energy_ledger || m.loop.floor_peaks;
    plain = !extras && detail::plain_steps(m, d, &z1, &r, as, 1) == 1;
    const S sd0 = d.sd;
    const detail::Exact e = plain ? detail::Exact::kDone : detail::finish_exact(m, d, d.z, z1, r, a0, a1);
    if (e == detail::Exact::kDone) {
      if (extras) detail::keep_extras(m, d, z1, a0, a1, sd0);
      d.z = z1;
    }
    careful = e == detail::Exact::kCareful;
    if (e == detail::Exact::kDiverged) ++d.count.divergences;
  }

  if constexpr (Dev::kKind == DeviceKind::kVines) {
    if (careful) {
      // 2b. Sub-stepped step through (possible) contacts; rolled back whole
      // if it diverged (rare steps: the copy is affordable here).
      detail::close_elastic_run(m, d);
      const Data<S, N, Dev> before = d;
      if (m.loop.contact_scheme == ContactScheme::kBounded) substep_bounded(m, d, a0, a1);
      else substep_through(m, d, a0, a1);
      detail::refresh_floors(m, d);
      if (detail::diverged(m, d.z, d.xf, d.s, d.sd)) {
        const Counters count = d.count;
        d = before;
        d.count = count;
        ++d.count.divergences;
      }
    }
  }

  // 3. Bookkeeping (a plain step has done its own).
  if (!plain) detail::end_step(d, d.vt);
  d.a_prev = a1;
  ++d.count.steps;
  if (m.loop.floor_peaks) {
    const double strain_now = static_cast<double>(m.strain.eval(d.z, S(0)));
    if (strain_now > d.last_strain) d.strain_increments += strain_now - d.last_strain;
    d.last_strain = strain_now;
  }
  if (m.loop.energy_ledger) detail::close_ledger(m, d);
}

namespace detail {

// Exact steps from a[0] on, as many as follow one another (the VI NES
// particle free and clear of the walls, finite samples, no energy ledger or
// per-floor peaks to keep), with step()'s arithmetic, block by block: first
// the frame through the block (it does not depend on the particle while the
// particle flies free), then the particle, guards, peaks and E_e step by
// step (plain_steps, and finish_exact for a step that is not plain), up to
// the first step that needs care or diverged. Blocks grow from one step, so
// a run that ends at once wastes little frame work. Returns the samples
// consumed.
template <typename S, int N, typename Dev, typename T>
std::size_t run_exact(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, const T* a, std::size_t n) {
  using VecX = typename Model<S, N, Dev>::VecX;
  // Largest block: 32 steps, or fewer when the states would pass 8 KB of
  // stack (frames of many stories).
  constexpr int kFit = static_cast<int>(8192 / sizeof(VecX));
  constexpr int kMax = kFit < 4 ? 4 : (kFit > 32 ? 32 : kFit);
  if (m.loop.energy_ledger || m.loop.floor_peaks) return 0;
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    if (d.mode != Mode::kFree) return 0;
  }
  VecX zs[kMax];  // the frame after each step of the block
  StepRead<S> rs[kMax];
  S as[kMax + 1];  // the block's samples, after the one before it
  std::size_t done = 0;
  for (int block = 1; done < n; block = block < kMax ? 2 * block : kMax) {
    const int nb = n - done < static_cast<std::size_t>(block) ? static_cast<int>(n - done) : block;
    // 1. The frame, over the block's finite samples.
    as[0] = d.a_prev;
    int nf = 0;
    for (; nf < nb; ++nf) {
      const S a1 = static_cast<S>(a[done + static_cast<std::size_t>(nf)]);
      if (VINES_UNLIKELY(!std::isfinite(a1))) break;
      as[nf + 1] = a1;
    }
    linear_steps(m, d.z, zs, rs, as, nf);
    // 2. The rest, step by step: plain steps in a run, any other in full.
    int j = 0;
    while (j < nf) {
      j += plain_steps(m, d, zs + j, rs + j, as + j, nf - j);
      if (j == nf || finish_exact(m, d, j ? zs[j - 1] : d.z, zs[j], rs[j], as[j], as[j + 1]) != Exact::kDone) break;
      end_step(d, d.vt);
      ++j;
    }
    if (j > 0) {
      d.z = zs[j - 1];
      d.a_prev = as[j];
    }
    d.count.steps += j;
    done += static_cast<std::size_t>(j);
    if (j < nb) break;
  }
  return done;
}

}  // namespace detail

// Feeds the samples a[0..n) in order: the same result, bit for bit, as
// step() on each.
template <typename S, int N, typename Dev, typename T>
void run(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, const T* a, std::size_t n) {
  std::size_t i = 0;
  while (i < n) {
    i += detail::run_exact(m, d, a + i, n - i);
    if (i < n) step(m, d, static_cast<S>(a[i++]));
  }
}

// E_e so far [J s].
template <typename S, int N, typename Dev>
double elastic_energy(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  return d.ee_open ? d.ee_sum - static_cast<double>(m.ee_boundary.eval(d.z, S(0))) : d.ee_sum;
}

// Floor displacements and velocities now (outputs only).
template <typename S, int N, typename Dev>
Eigen::Matrix<S, N, 1> floor_displacements(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  return m.floor_x(d.z);
}
template <typename S, int N, typename Dev>
Eigen::Matrix<S, N, 1> floor_velocities(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  return m.floor_v(d.z);
}

// Absolute floor accelerations [m/s^2] at the current time (outputs only).
template <typename S, int N, typename Dev>
Eigen::Matrix<S, N, 1> absolute_accel(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  const Eigen::Matrix<S, N, 1> x = m.floor_x(d.z), v = m.floor_v(d.z);
  Eigen::Matrix<S, N, 1> acc = -(m.minv_k * x) - m.minv_c * v;
  S f_floor = S(0);
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    const auto& t = m.dev.design;
    f_floor = static_cast<S>(t.k) * (d.z(N) - x(m.floor)) + static_cast<S>(t.c) * (d.z(2 * N + 1) - v(m.floor));
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) f_floor = -d.contact_force;
  acc(m.floor) += f_floor * m.inv_floor_mass;
  return acc;
}

}  // namespace vines
