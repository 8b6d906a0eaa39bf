// Scene parameters: the plain data a scene file (or a configure message on a
// link) turns into. Everything is SI and double; the model builder checks it
// and turns it into an immutable Model<S, N, Device>. No heap, no pointers.
#pragma once

#include <cstdint>

namespace vines {

// Capacity of the parameter arrays; a frame's actual story count is a
// compile-time N <= kMaxStories chosen by the caller.
inline constexpr int kMaxStories = 40;

// g used for every g <-> m/s^2 conversion (docs/model.md section 1, units).
inline constexpr double kGravity = 9.80665;

enum class DampingRule : std::uint8_t {
  kStiffnessProportional,  // C = c_k * K (the paper: c_k = 0.0129 s)
  kRayleigh,               // C = a0 M + a1 K, fitted to two modal ratios
  kModal,                  // the same ratio zeta on every mode
};

struct FrameParams {
  int stories = 10;
  double mass_kg[kMaxStories] = {};
  double stiffness_n_per_m[kMaxStories] = {};
  DampingRule damping = DampingRule::kStiffnessProportional;
  double stiffness_damping_s = 0.0129;      // kStiffnessProportional
  double rayleigh_zeta[2] = {0.02, 0.02};  // kRayleigh: target ratios...
  int rayleigh_modes[2] = {1, 2};          // ...on these modes (1-based)
  double modal_zeta = 0.02;                // kModal
  // Damage: every story stiffness is scaled by eta_k, and story i also by
  // stiffness_scales[i] (bottom first). Damping is built from the scaled K
  // (C = c_k K stays proportional to what the frame really has).
  double stiffness_scale = 1.0;
  double stiffness_scales[kMaxStories] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1,
                                          1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
};
static_assert(kMaxStories == 40, "stiffness_scales' initialiser lists kMaxStories ones");

// Story i's stiffness as built: nominal, times eta_k, times its own factor.
inline double story_stiffness(const FrameParams& f, int i) {
  return f.stiffness_n_per_m[i] * f.stiffness_scale * f.stiffness_scales[i];
}

// The frame undamaged: what devices are designed on.
inline FrameParams undamaged(FrameParams f) {
  f.stiffness_scale = 1.0;
  for (double& s : f.stiffness_scales) s = 1.0;
  return f;
}

enum class DeviceKind : std::uint8_t { kNone, kTmd, kVines };

enum class ContactLaw : std::uint8_t {
  kHertz,        // F = C d^{3/2}
  kTsuji,        // + D(eps) sqrt(C m*) d^{1/4} d'
  kKuwabara,     // + (3/2) C tau d^{1/2} d'
  kRestitution,  // instantaneous, Newton's law with eps
};

struct TmdParams {
  // Den Hartog design (Eq. 18) from the mass ratio on the nominal frame's
  // first mode, unless k and c are given (> 0).
  double k_n_per_m = 0.0;
  double c_ns_per_m = 0.0;
  double initial_position_m = 0.0;  // relative to its floor
  double initial_velocity_mps = 0.0;
};

struct VinesParams {
  // Sphere: mass comes from DeviceParams (mass ratio or mass); radius from
  // mass and density unless radius_m > 0 (then the mass follows from it).
  double radius_m = 0.0;
  double density_kg_m3 = 8000.0;
  double young_pa = 210e9;
  double poisson = 0.3;
  double wall_young_pa = 210e9;
  double wall_poisson = 0.3;
  // Box: length b = beta * 2R unless box_length_m > 0.
  double beta = 1.35;
  double box_length_m = 0.0;
  ContactLaw law = ContactLaw::kKuwabara;
  double eps = 0.7;       // restitution target (Tsuji, Kuwabara, Restitution)
  double v_ref_mps = 0.5; // Kuwabara: tau calibrated at this impact speed...
  double tau_s = 0.0;     // ...unless tau is given (> 0)
  // Initial particle state relative to the box centre. The default puts the
  // particle at rest against the left wall (u = -gap).
  bool start_at_left_wall = true;
  double initial_position_m = 0.0;
  double initial_velocity_mps = 0.0;
};

struct DeviceParams {
  DeviceKind kind = DeviceKind::kNone;
  int floor = 0;  // 1-based floor the device sits on; 0 means the top floor
  // Device mass: mass_kg if > 0, else mass_ratio times the first-mode
  // effective mass of the nominal (undamaged) frame.
  double mass_ratio = 0.05;
  double mass_kg = 0.0;
  TmdParams tmd;
  VinesParams vines;
};

// How a sensor step in which the VI NES particle may touch a wall is
// integrated (substep.hpp, substep_bounded.hpp).
enum class ContactScheme : std::uint8_t {
  kAdaptive,  // adaptive Dormand-Prince sub-steps to contact_rtol, events to rounding
  kBounded,   // at most bounded_substeps sub-steps a step: worst-case work fixed by construction
  kSplit,     // the overlap's scalar equation alone, the frame and the particle exact (substep_split.hpp)
};

// Range of loop.bounded_substeps (sub-steps a sensor step may take).
inline constexpr int kMinBoundedSubsteps = 2;
inline constexpr int kMaxBoundedSubsteps = 64;
// Range of loop.split_steps (Runge-Kutta steps per unit of a contact's own
// scale in w, substep_split.hpp).
inline constexpr int kMinSplitSteps = 4;
inline constexpr int kMaxSplitSteps = 1024;
// Runge-Kutta steps a sensor step may take, in loop.split_steps: an impact
// takes about 2 (and a step at 50 Hz may hold more than one).
inline constexpr int kSplitCap = 16;

struct LoopParams {
  double sensor_rate_hz = 1000.0;
  // Contact sub-stepping (adaptive embedded Runge-Kutta inside a step).
  double contact_rtol = 1e-10;
  int max_substeps_per_step = 4096;
  // Contacts shallower than this are not counted (rounding at rest contact).
  double contact_count_depth_m = 1e-9;
  // Outputs nobody asked for are not computed: the energy ledger (balance of
  // input, dissipation and storage), and per-floor peaks and drifts with the
  // strain-energy increments (the top-floor peak and E_e are always kept).
  bool energy_ledger = false;
  bool floor_peaks = false;
  // Divergence guard: a floor (or the TMD) farther than this from the ground
  // [m], or any non-finite state, rolls the step back (see sim.hpp).
  double divergence_limit_m = 100.0;
  // Contact integration: the adaptive scheme (contact_rtol,
  // max_substeps_per_step) or the bounded one, which takes at most
  // bounded_substeps Dormand-Prince sub-steps in a sensor step whatever
  // happens in it (substep_bounded.hpp), or the split one, split_steps
  // Runge-Kutta steps of the overlap's scalar equation per unit of the
  // contact's own scale (substep_split.hpp).
  ContactScheme contact_scheme = ContactScheme::kAdaptive;
  int bounded_substeps = 6;
  int split_steps = 64;
};

// The fixed-point engine's scales (fixed/frame.hpp, fixed/vines_model.hpp;
// scene keys loop.fixed_*): the ground acceleration its units are made for
// [m/s^2], the modes' dynamic amplification they leave room for, and a speed
// that bounds the impacts [m/s]. Past them a run saturates (counted).
struct FixedParams {
  double accel_mps2 = 9.80665;
  double amplification = 10.0;
  double contact_speed_mps = 1.5;
};

struct SceneParams {
  FrameParams frame;
  DeviceParams device;
  LoopParams loop;
  FixedParams fixed;
};

}  // namespace vines
