#include "sim_host/reference/spec.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "vines/model/validate.hpp"

namespace vines::host::reference {
namespace {

[[noreturn]] void refuse(const char* field, const char* message, int index = -1) {
  std::string key = field;
  if (index >= 0) key += "[" + std::to_string(index) + "]";
  throw std::runtime_error(key + ": " + message);
}

}  // namespace

OdeSpec make_spec(const SceneParams& p) {
  const ParamError e = validate(p);
  if (!e.ok()) refuse(e.field, e.message, e.index);
  OdeSpec s;
  s.frame = build_host_frame(p.frame);
  s.kind = p.device.kind;
  s.law = p.device.vines.law;
  s.floor = p.device.floor > 0 ? p.device.floor - 1 : s.frame.n - 1;
  if (s.kind == DeviceKind::kNone) return s;

  // Devices are designed on the nominal (undamaged) frame, as in build_model.
  const HostModes nm = host_modes(build_host_frame(undamaged(p.frame)));
  const double mass = p.device.mass_kg > 0.0 ? p.device.mass_kg : p.device.mass_ratio * nm.m_eff[0];
  const double floor_mass = s.frame.m[static_cast<std::size_t>(s.floor)];
  if (s.kind == DeviceKind::kTmd) {
    s.tmd = design_tmd(p.device.tmd, mass, nm.m_eff[0], nm.omega[0]);
    s.tmd_x0 = p.device.tmd.initial_position_m;
    s.tmd_v0 = p.device.tmd.initial_velocity_mps;
    return s;
  }
  const VinesParams& vp = p.device.vines;
  s.vines = design_vines(vp, mass, floor_mass);
  if (!s.vines.ok) refuse("vines.eps", "tau could not be calibrated for this eps and v_ref");
  if (!(s.vines.gap > 0.0)) refuse("vines.box_length_m", "must be longer than the sphere diameter");
  s.y0 = vp.start_at_left_wall ? -s.vines.gap : vp.initial_position_m;
  if (std::fabs(s.y0) > s.vines.gap)
    refuse("vines.initial_position_m", "must lie within the free travel (-gap, +gap)");
  s.v0 = vp.initial_velocity_mps;
  s.wall_left = -s.vines.gap - s.y0;
  s.wall_right = s.vines.gap - s.y0;
  s.count_depth = p.loop.contact_count_depth_m;
  return s;
}

}  // namespace vines::host::reference
