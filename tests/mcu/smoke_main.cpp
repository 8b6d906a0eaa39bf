// MCU smoke image: the real firmware loop on the target (the toolchain's
// scalar: float on the Cortex-M4F, double on the Cortex-M7): builds the table-1 frame with the default VI NES
// (its default contact law, beta 1.35) and runs it at 1 kHz under a near-resonant sine,
// fed sample by sample. Checks invariants that hold in any scalar: the first
// frequency, contacts happen, the state stays finite, the energy balances.
// Reports through semihosting; exit status 0 = pass. It must stay heap-free:
// the link fails otherwise (mcu_image.cmake).
#include <cmath>
#include <cstring>

#include "semihost.h"
#include "vines/build/build_model.hpp"
#include "vines/model/frame_presets.hpp"
#include "vines/step/sim.hpp"

namespace {

using Scalar = VINES_MCU_SCALAR;  // from the toolchain file (cmake/arm-none-eabi.cmake)
using Dev = vines::VinesDevice<vines::VinesParams{}.law>;  // the scene's default law
constexpr int kStories = 10;
constexpr double kPi = 3.14159265358979323846;

// Static blocks: the model and the run's data never live on the stack.
vines::Model<Scalar, kStories, Dev> g_model;
vines::Data<Scalar, kStories, Dev> g_data;

const char* run_smoke(double* f1_hz, long* contacts) {
  vines::SceneParams scene;
  vines::apply_frame_preset(vines::FramePreset::kTable1, &scene.frame);
  scene.device.kind = vines::DeviceKind::kVines;
  scene.loop.energy_ledger = true;  // the smoke run checks the balance

  vines::SceneParams bad = scene;  // the checks must also refuse
  bad.device.vines.beta = 0.9;
  const vines::ParamError e = vines::validate(bad);
  if (e.ok() || std::strcmp(e.field, "vines.beta") != 0) return "beta 0.9 not refused";

  if (!vines::build_model(scene, &g_model).ok()) return "default VI NES scene refused";
  *f1_hz = g_model.modal.frequency_hz()(0);
  if (std::fabs(*f1_hz - 0.4946) > 5e-5) return "first frequency is not 0.4946 Hz";

  // 6 s of a 2 m/s^2 sine at 0.5 Hz, one sample per step.
  const double rate = scene.loop.sensor_rate_hz;
  auto ag = [&](long k) { return static_cast<Scalar>(2.0 * std::sin(2 * kPi * 0.5 * (k / rate))); };
  vines::init(g_model, g_data, ag(0));
  for (long k = 1; k <= 6000; ++k) {
    vines::step(g_model, g_data, ag(k));
    if (!std::isfinite(g_data.xt) || !std::isfinite(g_data.s)) return "state not finite";
  }
  *contacts = static_cast<long>(g_data.count.contacts);
  if (*contacts < 1) return "no contact in 6 s of near-resonant shaking";
  if (!(g_data.ledger.relative_residual() < 1e-3)) return "energy balance off by more than 1e-3";
  return nullptr;
}

}  // namespace

int main() {
  double f1_hz = 0.0;
  long contacts = 0;
  if (const char* failure = run_smoke(&f1_hz, &contacts)) {
    vines_semihost_puts("vines mcu smoke: FAIL: ");
    vines_semihost_puts(failure);
    vines_semihost_puts("\n");
    return 1;
  }
  vines_semihost_puts("vines mcu smoke: ok (f1 = ");
  vines_semihost_put_int(std::llround(f1_hz * 1e6));
  vines_semihost_puts(" uHz, contacts ");
  vines_semihost_put_int(contacts);
  vines_semihost_puts(")\n");
  return 0;
}
