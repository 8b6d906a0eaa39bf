// Parameter checks shared by every front end (scene files on the host,
// configure messages on a link). A scene either passes or is refused with the
// name of the offending field and the reason; the loop never sees bad numbers.
#pragma once

#include <cmath>

#include "vines/model/contact_laws.hpp"
#include "vines/model/param_error.hpp"
#include "vines/model/params.hpp"

namespace vines {

inline ParamError validate(const FrameParams& f) {
  using detail::finite_positive;
  if (f.stories < 1 || f.stories > kMaxStories)
    return {"frame.stories", "must be between 1 and 40"};
  for (int i = 0; i < f.stories; ++i) {
    if (!finite_positive(f.mass_kg[i])) return {"frame.masses", "must be finite and > 0", i};
    if (!finite_positive(f.stiffness_n_per_m[i]))
      return {"frame.stiffnesses", "must be finite and > 0", i};
  }
  if (!finite_positive(f.stiffness_scale) || f.stiffness_scale > 10.0)
    return {"frame.stiffness_scale", "must be in (0, 10]"};
  for (int i = 0; i < f.stories; ++i)
    if (!finite_positive(f.stiffness_scales[i]) || f.stiffness_scales[i] > 10.0)
      return {"frame.stiffness_scales", "must be in (0, 10]", i};
  switch (f.damping) {
    case DampingRule::kStiffnessProportional:
      if (!std::isfinite(f.stiffness_damping_s) || f.stiffness_damping_s < 0.0)
        return {"frame.stiffness_damping_s", "must be finite and >= 0"};
      break;
    case DampingRule::kRayleigh:
      for (int j = 0; j < 2; ++j) {
        if (!std::isfinite(f.rayleigh_zeta[j]) || f.rayleigh_zeta[j] < 0.0 ||
            f.rayleigh_zeta[j] >= 1.0)
          return {"frame.rayleigh_zeta", "must be in [0, 1)", j};
        if (f.rayleigh_modes[j] < 1 || f.rayleigh_modes[j] > f.stories)
          return {"frame.rayleigh_modes", "must name modes between 1 and the story count", j};
      }
      if (f.rayleigh_modes[0] == f.rayleigh_modes[1])
        return {"frame.rayleigh_modes", "must name two different modes"};
      break;
    case DampingRule::kModal:
      if (!std::isfinite(f.modal_zeta) || f.modal_zeta < 0.0 || f.modal_zeta >= 1.0)
        return {"frame.modal_zeta", "must be in [0, 1)"};
      break;
  }
  return {};
}

inline ParamError validate(const DeviceParams& d, int stories) {
  using detail::finite_positive;
  if (d.kind == DeviceKind::kNone) return {};
  if (d.floor < 0 || d.floor > stories)
    return {"device.floor", "must be between 1 and the story count (0 = top)"};
  if (d.mass_kg != 0.0 && !finite_positive(d.mass_kg)) return {"device.mass_kg", "must be finite and > 0"};
  if (d.mass_kg == 0.0 && (!finite_positive(d.mass_ratio) || d.mass_ratio > 1.0))
    return {"device.mass_ratio", "must be in (0, 1]"};
  if (d.kind == DeviceKind::kTmd) {
    const TmdParams& t = d.tmd;
    const bool given_k = t.k_n_per_m != 0.0, given_c = t.c_ns_per_m != 0.0;
    if (given_k && !finite_positive(t.k_n_per_m)) return {"tmd.k_n_per_m", "must be finite and > 0"};
    if (given_c && (!std::isfinite(t.c_ns_per_m) || t.c_ns_per_m < 0.0))
      return {"tmd.c_ns_per_m", "must be >= 0"};
    if (given_c && !given_k) return {"tmd.c_ns_per_m", "needs tmd.k_n_per_m as well"};
    if (!std::isfinite(t.initial_position_m)) return {"tmd.initial_position_m", "must be finite"};
    if (!std::isfinite(t.initial_velocity_mps))
      return {"tmd.initial_velocity_mps", "must be finite"};
    return {};
  }
  const VinesParams& v = d.vines;
  if (v.radius_m != 0.0 && !finite_positive(v.radius_m)) return {"vines.radius_m", "must be finite and > 0"};
  if (!finite_positive(v.density_kg_m3)) return {"vines.density_kg_m3", "must be finite and > 0"};
  if (!finite_positive(v.young_pa)) return {"vines.young_pa", "must be finite and > 0"};
  if (!finite_positive(v.wall_young_pa)) return {"vines.wall_young_pa", "must be finite and > 0"};
  if (!(v.poisson > -1.0 && v.poisson < 0.5)) return {"vines.poisson", "must be in (-1, 0.5)"};
  if (!(v.wall_poisson > -1.0 && v.wall_poisson < 0.5))
    return {"vines.wall_poisson", "must be in (-1, 0.5)"};
  if (v.box_length_m != 0.0) {
    if (!finite_positive(v.box_length_m)) return {"vines.box_length_m", "must be finite and > 0"};
  } else if (!(std::isfinite(v.beta) && v.beta > 1.0)) {
    return {"vines.beta", "must be a finite number > 1 (the box must be longer than the sphere)"};
  }
  // The law's own checks (eps, tau...).
  ParamError law_error{"vines.law", "is not a known contact law"};
  with_law(v.law, [&](auto law) { law_error = decltype(law)::check(v); });
  if (!law_error.ok()) return law_error;
  if (!v.start_at_left_wall) {
    if (!std::isfinite(v.initial_position_m)) return {"vines.initial_position_m", "must be finite"};
  }
  if (!std::isfinite(v.initial_velocity_mps))
    return {"vines.initial_velocity_mps", "must be finite"};
  return {};
}

inline ParamError validate(const LoopParams& l) {
  if (!(std::isfinite(l.sensor_rate_hz) && l.sensor_rate_hz >= 1.0 && l.sensor_rate_hz <= 1e6))
    return {"loop.sensor_rate_hz", "must be in [1, 1e6] Hz"};
  if (!(std::isfinite(l.contact_rtol) && l.contact_rtol >= 1e-14 && l.contact_rtol <= 1e-2))
    return {"loop.contact_rtol", "must be in [1e-14, 1e-2]"};
  if (l.max_substeps_per_step < 1 || l.max_substeps_per_step > 1000000)
    return {"loop.max_substeps_per_step", "must be in [1, 1e6]"};
  if (!(std::isfinite(l.contact_count_depth_m) && l.contact_count_depth_m >= 0.0))
    return {"loop.contact_count_depth_m", "must be >= 0"};
  if (!(std::isfinite(l.divergence_limit_m) && l.divergence_limit_m > 0.0))
    return {"loop.divergence_limit_m", "must be finite and > 0"};
  if (l.contact_scheme != ContactScheme::kAdaptive && l.contact_scheme != ContactScheme::kBounded &&
      l.contact_scheme != ContactScheme::kSplit)
    return {"loop.contact_scheme", "must be \"adaptive\", \"bounded\" or \"split\""};
  if (l.bounded_substeps < kMinBoundedSubsteps || l.bounded_substeps > kMaxBoundedSubsteps)
    return {"loop.bounded_substeps", "must be in [2, 64] (sub-steps per sensor step)"};
  if (l.split_steps < kMinSplitSteps || l.split_steps > kMaxSplitSteps)
    return {"loop.split_steps", "must be in [4, 1024] (Runge-Kutta steps per unit of a contact's scale)"};
  return {};
}

inline ParamError validate(const FixedParams& f) {
  if (!(std::isfinite(f.accel_mps2) && f.accel_mps2 > 0.0 && f.accel_mps2 <= 1000.0))
    return {"loop.fixed_accel_mps2", "must be in (0, 1000] m/s^2"};
  if (!(std::isfinite(f.amplification) && f.amplification >= 1.0 && f.amplification <= 1000.0))
    return {"loop.fixed_amplification", "must be in [1, 1000]"};
  if (!(std::isfinite(f.contact_speed_mps) && f.contact_speed_mps > 0.0 && f.contact_speed_mps <= 100.0))
    return {"loop.fixed_contact_speed_mps", "must be in (0, 100] m/s"};
  return {};
}

inline ParamError validate(const SceneParams& s) {
  ParamError e = validate(s.frame);
  if (!e.ok()) return e;
  e = validate(s.device, s.frame.stories);
  if (!e.ok()) return e;
  if (s.loop.contact_scheme == ContactScheme::kSplit && s.device.kind == DeviceKind::kVines &&
      law_impulsive(s.device.vines.law))
    return {"loop.contact_scheme", "\"split\" integrates a contact's force over time: it needs a law with a "
                                   "finite contact duration (vines.law), not an instantaneous impact"};
  e = validate(s.fixed);
  if (!e.ok()) return e;
  return validate(s.loop);
}

}  // namespace vines
