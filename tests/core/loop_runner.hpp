// Runs the firmware loop directly (Model and Data of vines/step/sim.hpp), as a
// board does: no host engine, no record reader. Core tests drive it with
// analytic inputs.
#pragma once

#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "vines/build/build_model.hpp"
#include "vines/model/frame_presets.hpp"
#include "vines/step/sim.hpp"

namespace vines::core_test {

// The paper's frame (Table 1) with a device, at a sensor rate.
inline SceneParams paper_scene(DeviceKind kind, double rate_hz) {
  SceneParams p;
  apply_frame_preset(FramePreset::kTable1, &p.frame);
  p.device.kind = kind;
  p.loop.sensor_rate_hz = rate_hz;
  return p;
}

// What a core test reads at the end of a run.
struct End {
  double top = 0;         // top-floor displacement, m
  double particle = 0;    // particle position, m (VI NES only)
  long long contacts = 0;
};

// Builds the model from p and steps it through the samples a.
template <typename Dev, int N = 10>
End run(const SceneParams& p, const std::vector<double>& a) {
  // Model and Data are large fixed-size blocks: on the heap of the test, not its stack.
  auto m = std::make_unique<Model<double, N, Dev>>();
  auto d = std::make_unique<Data<double, N, Dev>>();
  const ParamError e = build_model(p, m.get());
  EXPECT_TRUE(e.ok()) << (e.field ? e.field : "") << ": " << (e.message ? e.message : "");
  if (!e.ok()) return {};
  init(*m, *d, a[0]);
  for (std::size_t k = 1; k < a.size(); ++k) step(*m, *d, a[k]);
  End out;
  out.top = floor_displacements(*m, *d)(N - 1);
  if constexpr (Dev::kKind == DeviceKind::kVines) out.particle = m->dev.y0 + d->s;
  out.contacts = d->count.contacts;
  return out;
}

}  // namespace vines::core_test
