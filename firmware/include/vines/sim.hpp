// The fixed-step loop: one step per sensor sample, the ground acceleration
// linear between two samples. Pipeline of a step:
//   1. linear part + free particle: exact discretisation (no sub-steps);
//   2. if the particle touches a wall, or may during the step: adaptive
//      Dormand-Prince sub-steps through the step, contact starts and ends
//      located to rounding, capped per step (cap hits are counted);
//   3. outputs, running maxima (continuous in time), E_e, energy ledger.
// Work per step is bounded; no heap, no exceptions.
#pragma once

#include <cmath>

#include "vines/data.hpp"
#include "vines/model.hpp"
#include "vines/peaks.hpp"
#include "vines/substep.hpp"

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
  l.residual = l.input - stored - dissipated;
  l.max_abs_residual = std::fmax(l.max_abs_residual, std::fabs(l.residual));
  l.max_input = std::fmax(l.max_input, std::fmax(l.input, stored + dissipated));
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
  d.x = m.floor_x(d.z);
  d.v = m.floor_v(d.z);
  d.peak_x = d.x.cwiseAbs();
  d.peak_drift.setZero();
  d.peak_top = std::fabs(d.x(N - 1));
  d.substep = m.hs;
  if (m.loop.energy_ledger) detail::close_ledger(m, d);
  d.last_strain = static_cast<double>(m.strain.eval(d.z, S(0)));
}

namespace detail {

// Divergence check (MuJoCo-style warning): any non-finite state, a floor or
// the TMD beyond the model's limit, or a particle beyond a wall by more than
// its radius.
template <typename S, int N, typename Dev>
bool diverged(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  const S limit = static_cast<S>(m.loop.divergence_limit_m);
  if (!d.z.allFinite() || !(d.x.cwiseAbs().maxCoeff() <= limit)) return true;
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    if (!(std::fabs(d.z(N)) <= limit)) return true;
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    const S r = d.s - d.x(m.floor), radius = static_cast<S>(m.dev.design.radius);
    if (!(r >= m.dev.wall_left - radius && r <= m.dev.wall_right + radius) || !std::isfinite(d.sd))
      return true;
  }
  return false;
}

}  // namespace detail

// Advances the run by one sensor period to the next sample a1 [m/s^2].
// Guards: a non-finite sample is replaced by the last good one (hold) and
// counted; a step that diverges is rolled back to the state before it (the
// model holds its last good state, the clock advances) and counted. Both
// counters are outputs; neither stops the loop.
template <typename S, int N, typename Dev>
void step(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, S a1) {
  using VecX = typename Model<S, N, Dev>::VecX;
  if (!std::isfinite(a1)) {
    ++d.count.bad_samples;
    a1 = d.a_prev;
  }
  const S a0 = d.a_prev;
  const Data<S, N, Dev> before = d;
  const VecX z0 = d.z;
  const typename Model<S, N, Dev>::VecN x0 = d.x, v0 = d.v;

  bool exact = true;
  if constexpr (Dev::kKind == DeviceKind::kVines) exact = !needs_substeps(m, d, a0, a1);

  if (exact) {
    // 1. Exact step: linear part, free particle, and their step integrals.
    d.elastic_energy += static_cast<double>(m.strain_step.eval(z0, a0, a1));
    if (m.loop.energy_ledger) {
      d.ledger.input += static_cast<double>(m.input_step.eval(z0, a0, a1));
      d.ledger.damping += static_cast<double>(m.damping_step.eval(z0, a0, a1));
    }
    m.lti.step(d.z, a0, a1);
    if constexpr (Dev::kKind == DeviceKind::kVines) free_flight(m, d, a0, a1);
    d.x = m.floor_x(d.z);
    d.v = m.floor_v(d.z);
    detail::update_top_peak(m, d, z0, a0, x0(N - 1), v0(N - 1), a1);
    detail::update_peaks<S, N>(x0, v0, d.x, d.v, m.hs, d.peak_x, d.peak_drift);
  } else {
    // 2. Sub-stepped step through (possible) contacts.
    if constexpr (Dev::kKind == DeviceKind::kVines) substep_through(m, d, a0, a1);
  }

  if (detail::diverged(m, d)) {
    const Counters count = d.count;
    d = before;
    d.count = count;
    ++d.count.divergences;
  }

  // 3. Bookkeeping.
  if (std::fabs(d.v(N - 1)) > d.peak_top_velocity) d.peak_top_velocity = std::fabs(d.v(N - 1));
  ++d.k;
  ++d.count.steps;
  d.a_prev = a1;
  const double strain_now = static_cast<double>(m.strain.eval(d.z, S(0)));
  if (strain_now > d.last_strain) d.strain_increments += strain_now - d.last_strain;
  d.last_strain = strain_now;
  if (m.loop.energy_ledger) detail::close_ledger(m, d);
}

// Absolute floor accelerations [m/s^2] at the current time (outputs only).
template <typename S, int N, typename Dev>
Eigen::Matrix<S, N, 1> absolute_accel(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  Eigen::Matrix<S, N, 1> acc = -(m.minv_k * d.x) - m.minv_c * d.v;
  S f_floor = S(0);
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    const auto& t = m.dev.design;
    f_floor = static_cast<S>(t.k) * (d.z(N) - d.x(m.floor)) +
              static_cast<S>(t.c) * (d.z(2 * N + 1) - d.v(m.floor));
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) f_floor = -d.contact_force;
  acc(m.floor) += f_floor * m.inv_floor_mass;
  return acc;
}

}  // namespace vines
