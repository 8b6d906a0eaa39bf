// The fixed-step loop: one step per sensor sample, the ground acceleration
// linear between two samples. Pipeline of a step (step(), a function per
// stage; the exact step's pieces are in exact_step.hpp):
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
//      loop.bounded_substeps aimed sub-steps (substep_bounded.hpp); or, with
//      kSplit, the overlap's scalar equation alone, the frame and the
//      particle moved exactly by its force's moments (substep_split.hpp);
//   3. guards (non-finite input held, diverging steps rolled back), counters.
// Work per step is bounded; no heap, no exceptions. run() feeds a block of
// samples: the same steps, with runs of plain exact steps taken in blocks
// (the frame through the block, then the particle and the checks).
#pragma once

#include <cmath>
#include <cstddef>

#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/inline.hpp"
#include "vines/numeric/minmax.hpp"
#include "vines/step/exact_step.hpp"
#include "vines/step/peaks.hpp"
#include "vines/step/substep.hpp"
#include "vines/step/substep_bounded.hpp"
#include "vines/step/substep_split.hpp"

namespace vines {

namespace detail {

// Stored energies now and the balance residual, in S (the work sums read
// to S: in float the residual is good to a float's rounding of the energies,
// ~1e-7 of them).
template <typename S, int N, typename Dev>
void close_ledger(const Model<S, N, Dev>& m, Data<S, N, Dev>& d) {
  StepLedger<S>& l = d.ledger;
  l.kinetic = m.kinetic.eval(d.z, S(0));
  l.strain = m.strain.eval(d.z, S(0));
  l.device = m.device_potential.eval(d.z, S(0));
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    l.kinetic += S(0.5) * (m.dev.m * d.sd * d.sd);
    l.device += contact_energy(m, d);
  }
  const S input = l.input.value();
  const S dissipated = l.damping.value() + l.contact.value();
  const S stored = l.kinetic + l.strain + l.device;
  l.residual = l.initial + input - stored - dissipated;
  l.max_abs_residual = std::fmax(l.max_abs_residual, std::fabs(l.residual));
  l.max_input = std::fmax(l.max_input, std::fmax(l.initial + input, stored + dissipated));
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
  d.substep = m.period;
  if (m.loop.energy_ledger) {
    detail::close_ledger(m, d);  // the energy stored by the initial conditions
    d.ledger.initial = d.ledger.kinetic + d.ledger.strain + d.ledger.device;
    d.ledger.max_abs_residual = 0;
    detail::close_ledger(m, d);
  }
  d.last_strain = m.strain.eval(d.z, S(0));
}

namespace detail {

// 0. The sample: a non-finite one is replaced by the last good one (hold)
// and counted.
template <typename S, int N, typename Dev>
VINES_INLINE S guard_sample(Data<S, N, Dev>& d, S a1) {
  if (!std::isfinite(a1)) {
    ++d.count.bad_samples;
    a1 = d.a_prev;
  }
  return a1;
}

// 1.-2a. The exact step from a0 to a1, committed unless it needs care or
// diverged (counted; nothing changes): a plain step if it can be (*plain),
// else in full. Returns whether the step needs care: the VI NES particle is
// not free, or may touch a wall during it.
template <typename S, int N, typename Dev>
VINES_INLINE bool exact_stage(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a0, S a1, bool* plain) {
  using VecX = typename Model<S, N, Dev>::VecX;
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    if (d.mode != Mode::kFree) return true;
  }
  VecX z1;
  StepRead<S> r;
  const S as[2] = {a0, a1};
  linear_steps(m, d.z, &z1, &r, as, 1);
  const bool extras = m.loop.energy_ledger || m.loop.floor_peaks;
  *plain = !extras && plain_steps(m, d, &z1, &r, as, 1) == 1;
  const S sd0 = d.sd;
  const Exact e = *plain ? Exact::kDone : finish_exact(m, d, d.z, z1, r, a0, a1);
  if (e == Exact::kDone) {
    if (extras) keep_extras(m, d, z1, a0, a1, sd0);
    d.z = z1;
  }
  if (e == Exact::kDiverged) ++d.count.divergences;
  return e == Exact::kCareful;
}

// 2b. The VI NES step through (possible) contacts, sub-stepped by the
// loop's contact scheme; rolled back whole if it diverged (counted; rare
// steps: the copy is affordable here).
template <typename S, int N, typename Dev>
VINES_INLINE void careful_stage(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a0, S a1) {
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    close_elastic_run(m, d);
    const Data<S, N, Dev> before = d;
    if (m.loop.contact_scheme == ContactScheme::kBounded) {
      substep_bounded(m, d, a0, a1);
    } else if (m.loop.contact_scheme == ContactScheme::kSplit) {
      if constexpr (!Dev::kImpulsive) substep_split(m, d, a0, a1);
    } else {
      substep_through(m, d, a0, a1);
    }
    refresh_floors(m, d);
    if (diverged(m, d.z, d.xf, d.s, d.sd)) {
      const Counters count = d.count;
      d = before;
      d.count = count;
      ++d.count.divergences;
    }
  }
}

// 3. Bookkeeping: the clock and the top floor's speed (a plain step has
// done its own), the sample kept for the next step, strain increments and
// the energy ledger when asked for.
template <typename S, int N, typename Dev>
VINES_INLINE void end_of_step(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a1, bool plain) {
  if (!plain) end_step(d, d.vt);
  d.a_prev = a1;
  ++d.count.steps;
  if (m.loop.floor_peaks) {
    const S strain_now = m.strain.eval(d.z, S(0));
    if (strain_now > d.last_strain) d.strain_increments.add(strain_now - d.last_strain);
    d.last_strain = strain_now;
  }
  if (m.loop.energy_ledger) close_ledger(m, d);
}

}  // namespace detail

// Advances the run by one sensor period to the next sample a1 [m/s^2]: the
// pipeline of the top of this file, a function per stage. Guards: a
// non-finite sample is replaced by the last good one (hold) and counted; a
// step that diverges is rolled back to the state before it (the model holds
// its last good state, the clock advances) and counted. Both counters are
// outputs; neither stops the loop.
template <typename S, int N, typename Dev>
VINES_INLINE void step(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a1) {
  a1 = detail::guard_sample(d, a1);
  const S a0 = d.a_prev;
  bool plain = false;
  if (detail::exact_stage(m, d, a0, a1, &plain)) detail::careful_stage(m, d, a0, a1);
  detail::end_of_step(m, d, a1, plain);
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

// E_e so far [J s], in double (off the step: an output).
template <typename S, int N, typename Dev>
double elastic_energy(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  const double ee = d.ee_sum.wide();
  return d.ee_open ? ee - static_cast<double>(m.ee_boundary.eval(d.z, S(0))) : ee;
}

// When the top floor's |x| reached its running peak [s], in double: the
// sample's time plus the time into its step (a whole step: the next
// sample's, k h + h).
template <typename S, int N, typename Dev>
double peak_top_time(const Model<S, N, Dev>& m, const Carry<S>& d) {
  const double dt = d.peak_top_dt == m.period ? m.h : static_cast<double>(d.peak_top_dt);
  return static_cast<double>(d.peak_top_k) * m.h + dt;
}

// The energy ledger in double (vines::Ledger), as the host reads it.
template <typename S, int N, typename Dev>
Ledger energy_ledger(const Data<S, N, Dev>& d) {
  return ledger_of(d.ledger);
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
