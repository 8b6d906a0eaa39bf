// Contact scales of a VI NES scene, checked before any run (scene_limits.hpp).
#include "sim_host/scene/limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sim_host/scene/frame.hpp"
#include "vines/model/devices.hpp"

namespace vines::host {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// The key that sets the particle's size, as the scene gave it.
std::string size_key(const SceneParams& p) {
  if (p.device.vines.radius_m > 0.0) return "vines.radius_m";
  return p.device.mass_kg > 0.0 ? "device.mass_kg" : "device.mass_ratio";
}

}  // namespace

std::optional<LimitError> check_contact_scales(const SceneParams& p) {
  if (p.device.kind != DeviceKind::kVines) return std::nullopt;
  // The particle as the model designs it: its mass from the nominal frame's
  // first mode (as build_model), the Hertz prefactor C of the pair.
  const double m_eff1 = host_modes(build_host_frame(undamaged(p.frame))).m_eff[0];
  const double mass = p.device.mass_kg > 0.0 ? p.device.mass_kg : p.device.mass_ratio * m_eff1;
  const VinesDesign d = design_particle(p.device.vines, mass, 1.0);  // no law's calibration
  const VinesParams& v = p.device.vines;
  // The box's free travel, from beta (or the box's length) and the radius:
  // finite, and within what a building's device could be.
  constexpr double kMaxGapM = 1e3;
  if (!(std::isfinite(d.gap) && d.gap <= kMaxGapM)) {
    const bool by_box = v.box_length_m != 0.0;
    return LimitError{by_box ? "vines.box_length_m" : "vines.beta", "free travel beyond 1000 m",
                      "the sphere's free travel in the box is " + num(d.gap) + " m (" +
                          (by_box ? "vines.box_length_m " + num(v.box_length_m) : "vines.beta " + num(v.beta)) +
                          ", radius " + num(d.radius) + " m), beyond the " + num(kMaxGapM) +
                          " m a building's device could have"};
  }
  if (law_impulsive(v.law)) return std::nullopt;
  const double speed = std::max({v.v_ref_mps, std::fabs(v.initial_velocity_mps), kMinRepresentativeSpeed});
  const double t_c = contact::hertz_duration(d.mass, d.c, speed);
  const double overlap = contact::hertz_max_overlap(d.mass, d.c, speed);
  const std::string particle = "particle " + num(d.mass) + " kg, radius " + num(d.radius) + " m, vines.young_pa " +
                               num(v.young_pa) + ", vines.wall_young_pa " + num(v.wall_young_pa) + ", at " +
                               num(speed) + " m/s";

  // The smallest sub-step the loop may take in a sensor step of h.
  // (The split scheme follows a contact in steps of its own scale: no
  // sub-step of the sensor step bounds it.)
  const LoopParams& l = p.loop;
  const bool bounded = l.contact_scheme == ContactScheme::kBounded;
  const int most = bounded ? l.bounded_substeps : l.max_substeps_per_step;
  const std::string cap_key = bounded ? "loop.bounded_substeps" : "loop.max_substeps_per_step";
  const double substep = 1.0 / l.sensor_rate_hz / most;
  if (l.contact_scheme != ContactScheme::kSplit && t_c < kMinContactSubsteps * substep)
    return LimitError{size_key(p), "Hertz contact time under " + num(kMinContactSubsteps) + " smallest sub-steps",
                      "the Hertz contact lasts " + num(t_c) + " s (" + particle + "), under " +
                                       num(kMinContactSubsteps) + " of the smallest sub-steps, " + num(substep) +
                                       " s (loop.sensor_rate_hz " + num(l.sensor_rate_hz) + ", " + cap_key + " " +
                                       std::to_string(most) + "): no run can resolve its contacts; use a larger "
                                       "or heavier particle, softer materials, a higher " + cap_key +
                                       " or sensor rate"};
  // Hertz theory is for overlaps small against the radius: past it the
  // sphere would sink through the wall.
  if (overlap > d.radius)
    return LimitError{v.wall_young_pa < v.young_pa ? "vines.wall_young_pa" : "vines.young_pa",
                      "Hertz overlap deeper than the radius", "the Hertz overlap of an impact reaches " + num(overlap) + " m (" +
                                            particle + "), deeper than the radius " + num(d.radius) +
                                            " m: the materials are too soft for this particle"};
  return std::nullopt;
}

}  // namespace vines::host
