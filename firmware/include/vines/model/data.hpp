// The mutable data block of a run: state, running maxima, energy ledger and
// counters. Preallocated by the caller (static or stack), reset by init().
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "vines/model/contact_mode.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/compensated.hpp"

namespace vines {

// Energy ledger [J] as the host reads it (sim_host's RunTotals and Probe,
// the link's telemetry): in double whatever the loop's scalar. The loop
// keeps its own in its scalar (StepLedger below); ledger_of() reads it.
struct Ledger {
  double initial = 0;     // stored at t = 0 (initial conditions): energy put in too
  double input = 0;       // work of the inertial loads -m a_g on every mass
  double damping = 0;     // dissipated by the frame's (and TMD's) dashpots
  double contact = 0;     // dissipated in contacts (rate term, or impacts)
  double kinetic = 0;     // stored now: kinetic...
  double strain = 0;      // ...frame strain...
  double device = 0;      // ...TMD spring or contact elastic energy
  double residual = 0;    // initial + input - stored - dissipated, now
  double max_abs_residual = 0;
  double max_input = 0;   // largest of initial + input and stored + dissipated so far
  double relative_residual() const { return max_input > 0 ? max_abs_residual / max_input : 0; }
};

// The energy ledger a loop keeps, in its scalar S: the same quantities as
// Ledger, the three work sums over the record compensated
// (numeric/compensated.hpp: in double the plain sums, in float a float pair
// each), so that a float loop keeps them to about a double sum's accuracy
// with no double arithmetic on its step.
template <typename S>
struct StepLedger {
  S initial = S(0);
  numeric::Sum<S> input, damping, contact;
  S kinetic = S(0), strain = S(0), device = S(0);
  S residual = S(0);
  S max_abs_residual = S(0);
  S max_input = S(0);
  S relative_residual() const { return max_input > S(0) ? max_abs_residual / max_input : S(0); }
};

// The ledger in double, as the host reads it.
template <typename S>
Ledger ledger_of(const StepLedger<S>& l) {
  Ledger o;
  o.initial = static_cast<double>(l.initial);
  o.input = l.input.wide();
  o.damping = l.damping.wide();
  o.contact = l.contact.wide();
  o.kinetic = static_cast<double>(l.kinetic);
  o.strain = static_cast<double>(l.strain);
  o.device = static_cast<double>(l.device);
  o.residual = static_cast<double>(l.residual);
  o.max_abs_residual = static_cast<double>(l.max_abs_residual);
  o.max_input = static_cast<double>(l.max_input);
  return o;
}

struct Counters {
  std::int64_t steps = 0;
  std::int64_t careful_steps = 0;     // steps that needed sub-stepping
  std::int64_t substeps = 0;          // accepted sub-steps
  std::int64_t contact_substeps = 0;  // of which in contact (or stuck)
  std::int64_t rejected = 0;          // rejected sub-step attempts
  std::int64_t events = 0;            // located contact starts/ends/impacts
  std::int64_t contacts = 0;          // contacts deeper than the counting depth
  std::int64_t cap_hits = 0;          // steps that hit the sub-step cap
  std::int64_t max_substeps_in_step = 0;
  std::int64_t bad_samples = 0;   // non-finite ground samples, replaced by the last good one
  std::int64_t divergences = 0;   // steps rolled back by the divergence guard
  std::int64_t max_events_in_step = 0;  // most events applied in one step (bounded scheme)
};

// What a step carries to the next besides the linear state: the VI NES
// particle, the floors it moves against, the clock and the running outputs
// of exact steps. A run of plain exact steps keeps it in registers
// (plain_steps() in sim.hpp) and writes it back once at the end.
template <typename S>
struct Carry {
  // VI NES particle: s = displacement from its start (relative to ground).
  S s = S(0), sd = S(0);
  // The top floor and the device floor now.
  S xt = S(0), vt = S(0), xf = S(0), vf = S(0);
  std::int64_t k = 0;  // samples consumed; the state is at t = k h
  // Running maxima of the top floor: |x| continuous in time, |v| at the
  // samples. |x| is reached peak_top_dt [s] into the step from sample
  // peak_top_k: read the time with peak_top_time(m, d) (sim.hpp), in double.
  S peak_top = S(0), peak_top_velocity = S(0);
  std::int64_t peak_top_k = 0;
  S peak_top_dt = S(0);
  // E_e = integral of (1/2) x^T K x dt [J s] is ee_sum, less V(z) while a run
  // of exact steps is open (ee_open; see lyapunov_split): read it with
  // elastic_energy(m, d). A compensated sum in S (numeric/compensated.hpp).
  numeric::Sum<S> ee_sum;
  bool ee_open = false;
};

template <typename S, int N, typename Dev>
struct Data : Carry<S> {
  using M = Model<S, N, Dev>;
  using VecX = typename M::VecX;
  using VecN = typename M::VecN;

  VecX z = VecX::Zero();    // linear part
  S a_prev = S(0);          // ground acceleration at the current time
  Mode mode = Mode::kFree;  // VI NES
  S substep = S(0);         // last sub-step size in t (carried across steps)
  S substep_w = S(0);       // last sub-step size in w inside a contact
  S q = S(0);               // overlap^{1/4} of the current contact
  S contact_force = S(0);   // on the particle, positive to the right
  S contact_depth = S(0);   // deepest overlap of the current contact
  S max_overlap = S(0);     // deepest overlap of the run

  // Running maxima per floor (continuous in time, not just samples), only
  // with loop.floor_peaks; the top floor's are in Carry.
  VecN peak_x = VecN::Zero(), peak_drift = VecN::Zero();
  numeric::Sum<S> strain_increments;  // sum of positive increments of the strain energy [J] (floor_peaks)
  S last_strain = S(0);
  StepLedger<S> ledger;
  Counters count;

  // The time now [s], in double (off the step: outputs).
  double time(const M& m) const { return static_cast<double>(this->k) * m.h; }
};

}  // namespace vines
