// A scene's constants for the reference integrators, in double: the frame as
// simulated, the device designed with the firmware's own design functions
// (design_tmd, design_vines: the same model), the initial state.
#pragma once

#include "sim_host/scene/frame.hpp"
#include "vines/model/devices.hpp"
#include "vines/model/params.hpp"

namespace vines::host::reference {

struct OdeSpec {
  HostFrame frame;
  DeviceKind kind = DeviceKind::kNone;
  ContactLaw law = VinesParams{}.law;  // the scene's default
  int floor = 0;  // device floor, 0-based
  TmdDesign tmd;
  VinesDesign vines;
  double tmd_x0 = 0, tmd_v0 = 0;  // TMD relative to its floor at t = 0
  // Particle: starts at y0 from the box centre with velocity v0. Walls in the
  // coordinate r = w - x_floor, w the particle's displacement from its start
  // (docs/model.md section 3.3, particle coordinate: no cancellation against the
  // starting wall).
  double y0 = 0, v0 = 0;
  double wall_left = 0, wall_right = 0;
  double count_depth = 0;  // contacts shallower than this are not counted [m]
};

// Validates the parameters (vines::validate, then the design) and builds the
// spec; throws std::runtime_error naming the field at fault.
OdeSpec make_spec(const SceneParams& p);

}  // namespace vines::host::reference
