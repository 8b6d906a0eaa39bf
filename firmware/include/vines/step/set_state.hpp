// Setting the loop's physical state in the middle of a run (a digital twin's
// or an estimator's correction): the linear state z, the VI NES particle, and
// what follows from them, with the run's history kept. No heap, no
// exceptions; the caller finds z (the host solves the floors for it in
// double: sim_host/engines/engine_impl.hpp).
#pragma once

#include <cmath>

#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/step/exact_step.hpp"
#include "vines/step/sim.hpp"
#include "vines/step/substep_common.hpp"

namespace vines {

namespace detail {

// The energy the state stores now [J], in S: the frame's (and the TMD's)
// kinetic and strain energy, the VI NES particle's kinetic energy and its
// contact's elastic energy (close_ledger's stored part).
template <typename S, int N, typename Dev>
S stored_energy(const Model<S, N, Dev>& m, const Data<S, N, Dev>& d) {
  S e = m.kinetic.eval(d.z, S(0)) + m.strain.eval(d.z, S(0)) + m.device_potential.eval(d.z, S(0));
  if constexpr (Dev::kKind == DeviceKind::kVines) e += S(0.5) * (m.dev.m * d.sd * d.sd) + contact_energy(m, d);
  return e;
}

}  // namespace detail

// Whether a VI NES particle at s (its coordinate, Carry::s) lies strictly
// between the walls of a device floor at x_f (always true without a VI NES).
template <typename S, int N, typename Dev>
bool particle_clear(const Model<S, N, Dev>& m, S s, S xf) {
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    const S r = s - xf;
    return r > m.dev.wall_left && r < m.dev.wall_right;
  } else {
    (void)m;
    (void)s;
    (void)xf;
    return true;
  }
}

// Puts the run in the state z (the linear part, Model's layout) with the
// VI NES particle at s, s' (Carry::s, Carry::sd; ignored without a VI NES),
// in free flight: contact mode free, no contact force, overlap or contact
// depth. Kept: the clock, the sample, the running peaks and counters, the
// sub-step sizes. The floors the step carries are refreshed. E_e so far is
// unchanged (an open run of exact steps is closed on the old state; the next
// exact step opens one on the new) and goes on from the new state; the
// strain increments do not count the jump (last_strain is the new strain).
// With the energy ledger, the energy the new state stores less the old is
// energy put in (added to Ledger::initial): the balance holds across the
// change. Returns nullptr, or why it was refused (the data block is then
// untouched): a non-finite value, or the particle not strictly between the
// walls.
template <typename S, int N, typename Dev>
const char* set_state(const Model<S, N, Dev>& m, Data<S, N, Dev>& d, const typename Model<S, N, Dev>::VecX& z,
                      S s, S sd) {
  if (!z.allFinite()) return "the state is not finite";
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    if (!std::isfinite(s) || !std::isfinite(sd)) return "particle_x, particle_v: not finite";
    if (!particle_clear(m, s, m.dev_x(z))) return "particle_x: the particle would not lie strictly between the walls";
  }
  const bool ledger = m.loop.energy_ledger;
  const S before = ledger ? detail::stored_energy(m, d) : S(0);
  detail::close_elastic_run(m, d);
  d.z = z;
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    d.s = s;
    d.sd = sd;
    d.mode = Mode::kFree;
    d.contact_force = S(0);
    d.q = S(0);
    d.contact_depth = S(0);
  }
  detail::refresh_floors(m, d);
  d.last_strain = m.strain.eval(d.z, S(0));
  if (ledger) {
    d.ledger.initial += detail::stored_energy(m, d) - before;
    detail::close_ledger(m, d);
  }
  return nullptr;
}

}  // namespace vines
