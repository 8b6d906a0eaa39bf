// The whole VI NES step in fixed point on an FPU-less core (Cortex-M3,
// MPS2-AN385, soft-float ABI; issue 34): the paper's 10-story frame and
// sphere (the default law, Kuwabara-Kono) at 1 kHz, the Q3.28 split step (vines/fixed/vines_step.hpp)
// beside the double and the float loops' split scheme in software floating point, all at
// loop.split_steps = 16 (an impact in ~10 Runge-Kutta steps; the scene
// key's default 64 takes ~40), on the same 10 s of a two-tone ground motion
// that makes contacts (host: 8).
// Prints each one's instructions per step (worst and mean; timer 1 at 25 MHz
// under QEMU -icount shift=3: 5 instructions per tick) and the fixed model's
// and state's RAM; checks no saturation, no capped contact integration,
// contacts made, and the top floor's peak within 1e-3 of double's.
#include <cmath>
#include <cstdint>

#include "semihost.h"
#include "two_tone.hpp"
#include "vines/build/build_model.hpp"
#include "vines/fixed/vines_step.hpp"
#include "vines/hal/port.hpp"
#include "vines/model/frame_presets.hpp"
#include "vines/step/sim.hpp"

namespace {

constexpr vines::ContactLaw kLaw = vines::VinesParams{}.law;  // the default law (params.hpp)
using Dev = vines::VinesDevice<kLaw>;
vines::Model<double, 10, Dev> g_model;
vines::Data<double, 10, Dev> g_data;
vines::Model<float, 10, Dev> g_model_f;
vines::Data<float, 10, Dev> g_data_f;
constexpr double kAmax = 1.5;  // bound of |ground| below [m/s^2]
using FixedModel = decltype(vines::fixed::build_fixed_vines<28, vines::fixed::kFixedMoments, vines::LawOf<kLaw>>(
    g_model, vines::fixed::FixedScales{}));
FixedModel g_fixed;
vines::fixed::FixedVinesData<FixedModel> g_state;

double ground(long k) { return vines::mcu::two_tone(k, 0.2); }

}  // namespace

int main() {
  vines::hal::port_init();
  vines::SceneParams scene;
  vines::apply_frame_preset(vines::FramePreset::kTable1, &scene.frame);
  scene.device.kind = vines::DeviceKind::kVines;
  scene.device.vines.law = kLaw;
  scene.loop.contact_scheme = vines::ContactScheme::kSplit;
  scene.loop.split_steps = 16;  // docs/fixed_point.md: the cost of 64 beside it
  if (!vines::build_model(scene, &g_model).ok() || !vines::build_model(scene, &g_model_f).ok()) return 1;
  g_fixed = vines::fixed::build_fixed_vines<28, vines::fixed::kFixedMoments, vines::LawOf<kLaw>>(
      g_model, vines::fixed::FixedScales{kAmax, 10.0, 1.5});
  using Q = FixedModel::Q;
  vines::numeric::fixed_saturations() = 0;
  vines::init(g_model, g_data, ground(0));
  vines::init(g_model_f, g_data_f, static_cast<float>(ground(0)));
  vines::fixed::fixed_vines_init(g_fixed, g_state, Q(0), Q(ground(0) / kAmax));
  constexpr long kSteps = 10000;
  std::uint32_t worst_q = 0, worst_d = 0, worst_f = 0;
  std::uint64_t total_q = 0, total_d = 0, total_f = 0;
  for (long k = 1; k <= kSteps; ++k) {
    const double a1 = ground(k);
    const Q q1(a1 / kAmax);
    vines::hal::irq_off();
    std::uint32_t t = vines::hal::counter_now();
    vines::fixed::fixed_vines_step(g_fixed, g_state, q1);
    const std::uint32_t dq = vines::hal::counter_now() - t;
    t = vines::hal::counter_now();
    vines::step(g_model, g_data, a1);
    const std::uint32_t dd = vines::hal::counter_now() - t;
    t = vines::hal::counter_now();
    vines::step(g_model_f, g_data_f, static_cast<float>(a1));
    const std::uint32_t df = vines::hal::counter_now() - t;
    vines::hal::irq_on();
    worst_f = df > worst_f ? df : worst_f;
    total_f += df;
    worst_q = dq > worst_q ? dq : worst_q;
    worst_d = dd > worst_d ? dd : worst_d;
    total_q += dq;
    total_d += dd;
  }
  vines::mcu::put_step_cost("Q3.28 VI NES step", worst_q, total_q, kSteps);
  vines::mcu::put_step_cost("double VI NES step, split scheme (software FP)", worst_d, total_d, kSteps);
  vines::mcu::put_step_cost("float VI NES step, split scheme (software FP)", worst_f, total_f, kSteps);
  const double peak_q = static_cast<double>(g_state.frame.peak_top) * g_fixed.frame.top_length;
  const double peak_d = static_cast<double>(g_data.peak_top);
  vines_semihost_puts("RAM: fixed model ");
  vines_semihost_put_int(static_cast<long long>(sizeof(g_fixed)));
  vines_semihost_puts(" bytes, fixed state ");
  vines_semihost_put_int(static_cast<long long>(sizeof(g_state)));
  vines_semihost_puts(" bytes (double model ");
  vines_semihost_put_int(static_cast<long long>(sizeof(g_model)));
  vines_semihost_puts(", data ");
  vines_semihost_put_int(static_cast<long long>(sizeof(g_data)));
  vines_semihost_puts(")\ncontacts ");
  vines_semihost_put_int(g_state.contacts);
  vines_semihost_puts(" (double ");
  vines_semihost_put_int(g_data.count.contacts);
  vines_semihost_puts("), worst contact ");
  vines_semihost_put_int(g_state.max_contact_steps);
  vines_semihost_puts(" Runge-Kutta steps, capped ");
  vines_semihost_put_int(g_state.capped);
  vines_semihost_puts("; peak top / double's - 1, in 1e-9: ");
  vines_semihost_put_int(std::llround((peak_q / peak_d - 1.0) * 1e9));
  vines_semihost_puts("; saturations: ");
  vines_semihost_put_int(vines::numeric::fixed_saturations());
  vines_semihost_puts("\n");
  const bool ok = vines::numeric::fixed_saturations() == 0 && g_state.capped == 0 && g_state.contacts > 0 &&
                  std::fabs(peak_q / peak_d - 1.0) < 1e-3;
  vines_semihost_puts(ok ? "vines mcu fixed VI NES: ok\n" : "vines mcu fixed VI NES: FAIL\n");
  return ok ? 0 : 1;
}
