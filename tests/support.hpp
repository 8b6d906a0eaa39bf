// Helpers shared by the simulation tests: the El Centro record of docs/model.md section 6 and
// a run of a compiled engine over a sample sequence.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "host/record.hpp"
#include "sim_host/engines/engine.hpp"
#include "vines/model/frame_presets.hpp"

namespace vines::test {

inline std::string ground_motion(const std::string& file) {
  return std::string(VINES_DEFAULT_GROUND_MOTIONS) + "/" + file;
}

// El Centro as docs/model.md section 6 pins it (2688 points, dt 0.02 s, g),
// at the given sensor rate.
inline std::vector<double> elcentro(double rate_hz) {
  hal::RecordSpec spec;
  spec.path = ground_motion("elcentro_1940_ns_2688pts_dt002_time_g.dat");
  return hal::resample(hal::load_record(spec), rate_hz);
}

// The paper's frame with a device (kNone, kTmd or kVines with `law`).
inline SceneParams paper_scene(DeviceKind kind, ContactLaw law = ContactLaw::kKuwabara,
                               double rate_hz = 1000.0) {
  SceneParams p;
  apply_frame_preset(FramePreset::kTable1, &p.frame);
  p.device.kind = kind;
  p.device.vines.law = law;
  p.loop.sensor_rate_hz = rate_hz;
  p.loop.energy_ledger = true;  // the tests check the balance and every floor
  p.loop.floor_peaks = true;
  return p;
}

struct Outcome {
  host::RunTotals totals;
  host::Snapshot last;
};

inline Outcome run(const SceneParams& p, const std::vector<double>& a,
                   host::Scalar scalar = host::Scalar::kDouble) {
  auto eng = host::make_engine(p, scalar);
  EXPECT_NE(eng, nullptr);
  if (!eng) return {};
  const ParamError e = eng->build(p);
  EXPECT_TRUE(e.ok()) << (e.field ? e.field : "") << ": " << (e.message ? e.message : "");
  eng->init(a[0]);
  for (std::size_t k = 1; k < a.size(); ++k) eng->step(a[k]);
  return {eng->totals(), eng->snapshot()};
}

}  // namespace vines::test
