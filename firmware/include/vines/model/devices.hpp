// The devices a frame can carry, as compile-time policies: a scene with no
// device compiles no device code, and a VI NES compiles only its contact law
// (one of contact_laws.hpp).
// Each has a design step (parameters -> constants) done once in double.
#pragma once

#include <cmath>

#include "vines/model/contact.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/params.hpp"

namespace vines {

struct NoDevice {
  static constexpr DeviceKind kKind = DeviceKind::kNone;
};
struct TmdDevice {
  static constexpr DeviceKind kKind = DeviceKind::kTmd;
};
template <ContactLaw L>
struct VinesDevice {
  static constexpr DeviceKind kKind = DeviceKind::kVines;
  static constexpr ContactLaw kLaw = L;
  // Its law's impacts are instantaneous (contact_laws.hpp, kImpulsive).
  static constexpr bool kImpulsive = LawOf<L>::kImpulsive;
};

// ---- TMD: Den Hartog (Eq. 18) on the nominal frame's first mode ----
struct TmdDesign {
  double mass = 0, k = 0, c = 0;
  double mu = 0, lambda = 0, xi = 0;  // design ratios (0 when k, c were given)
  double omega = 0;                   // TMD circular frequency sqrt(k/m)
};

// mu = m_tmd / first-mode effective mass (the paper's definition of the ratio).
inline TmdDesign design_tmd(const TmdParams& p, double mass, double m_eff1, double omega1) {
  TmdDesign d;
  d.mass = mass;
  if (p.k_n_per_m > 0.0) {
    d.k = p.k_n_per_m;
    d.c = p.c_ns_per_m;
  } else {
    d.mu = mass / m_eff1;
    d.lambda = 1.0 / (1.0 + d.mu);
    d.xi = std::sqrt(3.0 * d.mu / (8.0 * (1.0 + d.mu)));
    const double w = d.lambda * omega1;
    d.k = mass * w * w;
    d.c = 2.0 * d.xi * mass * w;
  }
  d.omega = std::sqrt(d.k / mass);
  return d;
}

// ---- VI NES: sphere, box, then the law's design step (contact_laws.hpp) ----
// The sphere, the box and the Hertz pair, before any law's step.
inline VinesDesign design_particle(const VinesParams& p, double mass, double floor_mass) {
  constexpr double kPi = 3.14159265358979323846;
  VinesDesign d;
  if (p.radius_m > 0.0) {
    d.radius = p.radius_m;
    d.mass = p.density_kg_m3 * 4.0 / 3.0 * kPi * d.radius * d.radius * d.radius;
  } else {
    d.mass = mass;
    d.radius = std::cbrt(3.0 * mass / (4.0 * kPi * p.density_kg_m3));
  }
  d.box_length = p.box_length_m > 0.0 ? p.box_length_m : p.beta * 2.0 * d.radius;
  d.gap = 0.5 * d.box_length - d.radius;
  d.c = contact::hertz_c(p.young_pa, p.poisson, p.wall_young_pa, p.wall_poisson, d.radius);
  d.m_star = d.mass * floor_mass / (d.mass + floor_mass);
  d.v_ref = p.v_ref_mps;
  return d;
}

inline VinesDesign design_vines(const VinesParams& p, double mass, double floor_mass) {
  VinesDesign d = design_particle(p, mass, floor_mass);
  with_law(p.law, [&](auto law) { decltype(law)::design(p, &d); });
  return d;
}

}  // namespace vines
