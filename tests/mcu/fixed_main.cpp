// Fixed-point image for an FPU-less core (Cortex-M3, MPS2-AN385, soft-float
// ABI): the bare frame's modal exact step in Q3.28 (vines/fixed/modal.hpp)
// against the same step in double (software floating point here), 20 s of a
// two-tone ground motion at 1 kHz. Checks the top-floor error and that
// nothing saturated; prints the instructions per step of both (timer 1 at
// 25 MHz under QEMU -icount shift=3: 5 instructions per tick).
#include <cmath>
#include <cstdint>

#include "semihost.h"
#include "two_tone.hpp"
#include "vines/build/build_model.hpp"
#include "vines/fixed/modal.hpp"
#include "vines/hal/port.hpp"
#include "vines/model/frame_presets.hpp"

namespace {

using Q = vines::numeric::Fixed<28>;
vines::Model<double, 10, vines::NoDevice> g_model;

double ground(long k) { return vines::mcu::two_tone(k, 2.0); }

}  // namespace

int main() {
  vines::hal::port_init();
  vines::SceneParams scene;
  vines::apply_frame_preset(vines::FramePreset::kTable1, &scene.frame);
  if (!vines::build_model(scene, &g_model).ok()) return 1;
  constexpr double kAmax = 3.0;  // bound of |ground| above
  const auto scales = vines::numeric::modal_scales<10>(g_model.modal.omega, g_model.modal.gamma, kAmax, 10.0);
  const auto lq = vines::numeric::scaled_modal<28, 10>(g_model.lti, scales);
  using ZD = decltype(g_model)::VecX;
  ZD zd = ZD::Zero();
  Eigen::Matrix<Q, ZD::RowsAtCompileTime, 1> zq;
  zq.setConstant(Q(0));
  vines::numeric::fixed_saturations() = 0;
  constexpr long kSteps = 20000;
  std::uint32_t worst_q = 0, worst_d = 0;
  std::uint64_t total_q = 0, total_d = 0;
  double peak = 0, max_err = 0;
  for (long k = 1; k <= kSteps; ++k) {
    const double a0 = ground(k - 1), a1 = ground(k);
    const Q q0(a0 / kAmax), q1(a1 / kAmax);
    vines::hal::irq_off();
    std::uint32_t t = vines::hal::counter_now();
    lq.step(zq, q0, q1);
    const std::uint32_t dq = vines::hal::counter_now() - t;
    t = vines::hal::counter_now();
    g_model.lti.step(zd, a0, a1);
    const std::uint32_t dd = vines::hal::counter_now() - t;
    vines::hal::irq_on();
    worst_q = dq > worst_q ? dq : worst_q;
    worst_d = dd > worst_d ? dd : worst_d;
    total_q += dq;
    total_d += dd;
    double xq = 0;
    for (int j = 0; j < 10; ++j) xq += g_model.rows.top(j) * scales.q(j) * static_cast<double>(zq(j));
    const double xd = g_model.top_x(zd);
    peak = std::fmax(peak, std::fabs(xd));
    max_err = std::fmax(max_err, std::fabs(xq - xd));
  }
  vines::mcu::put_step_cost("Q3.28 modal step", worst_q, total_q, kSteps);
  vines::mcu::put_step_cost("double modal step (software FP)", worst_d, total_d, kSteps);
  vines_semihost_puts("largest top-floor error / peak, in 1e-9: ");
  vines_semihost_put_int(std::llround(max_err / peak * 1e9));
  vines_semihost_puts("; saturations: ");
  vines_semihost_put_int(vines::numeric::fixed_saturations());
  vines_semihost_puts("\n");
  const bool ok = vines::numeric::fixed_saturations() == 0 && max_err < 5e-5 * peak && peak > 1e-3;
  vines_semihost_puts(ok ? "vines mcu fixed: ok\n" : "vines mcu fixed: FAIL\n");
  return ok ? 0 : 1;
}
