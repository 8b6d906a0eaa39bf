// What a built model knows, for reports (Engine::info()): every engine's,
// whatever scalar it steps in.
#pragma once

#include "sim_host/engines/engine.hpp"
#include "vines/model/model.hpp"

namespace vines::host {

template <typename S, int N, typename Dev>
ModelInfo model_info(const Model<S, N, Dev>& m) {
  ModelInfo out;
  out.stories = N;
  for (int j = 0; j < N; ++j) {
    out.frequency_hz[j] = m.modal.frequency_hz()(j);
    out.zeta[j] = m.modal.zeta(j);
    out.gamma[j] = m.modal.gamma(j);
    out.m_eff[j] = m.modal.m_eff(j);
    // Shapes normalised to the top floor's participation: phi_j * gamma_j.
    for (int i = 0; i < N; ++i) out.mode_shapes[j][i] = m.modal.phi(i, j) * m.modal.gamma(j);
  }
  out.total_mass = m.frame.m.sum();
  out.sensor_period = m.h;
  out.device_floor = m.floor + 1;
  if constexpr (Dev::kKind == DeviceKind::kTmd) out.tmd = m.dev.design;
  if constexpr (Dev::kKind == DeviceKind::kVines) out.vines = m.dev.design;
  return out;
}

}  // namespace vines::host
