// Scene parameters refused at load because no run could keep them stable or
// physical (docs/model.md, "Refused at load"): a contact far shorter than the
// sub-steps the loop may take, or a Hertz overlap deeper than the sphere.
#pragma once

#include <optional>
#include <string>

#include "vines/model/params.hpp"

namespace vines::host {

// A contact must span at least this many of the smallest sub-steps the loop
// may take in a sensor step (h / max_substeps_per_step, or h / bounded_substeps).
inline constexpr double kMinContactSubsteps = 16.0;
// Impact speed the contact scales are taken at, at least [m/s]: the size of the
// fastest floor-to-particle speeds under the shipped records.
inline constexpr double kMinRepresentativeSpeed = 1.0;

// The key at fault, the rule broken (no figures: it groups refusals) and why,
// with the figures.
struct LimitError {
  std::string key;
  std::string rule;
  std::string message;
};

// The VI NES contact scales of validated parameters (vines::validate passed):
// nothing for other devices and for the restitution law (no contact time,
// no overlap), else the first limit broken.
std::optional<LimitError> check_contact_scales(const SceneParams& p);

}  // namespace vines::host
