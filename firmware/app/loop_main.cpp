// The firmware application: the sensor loop as it runs on the board.
//   1. Reads a scene (SceneParams) and the sample count from the link
//      (vines/hal/link_protocol.hpp), validates it and builds the model of
//      the image's device (VINES_APP_DEVICE: tmd or vines, Kuwabara law) and
//      of the bare frame, which runs in lockstep for x_r and E_r.
//   2. At every sensor tick: one sample from the link (LinkSource, a
//      GroundSource), one step of the device model timed on the port's
//      counter with interrupts masked (the deadline monitor holds it against
//      the budget), one step of the bare frame, one telemetry line
//      "f TICKS" (exact free step) or "c TICKS" (sub-stepped: contact, or a
//      wall within reach).
//   3. The summary as "d KEY HEXBITS" / "i KEY INT" lines, then "end".
// Exit status 0, or 1 with a message on the console if the input is refused.
// The same source builds for the MCU (hal/mcu/port_mps2.cpp) and the host
// (hal/host/port.cpp): the HAL backend is picked by the build.
#include <cstdint>

#include "link_source.hpp"
#include "telemetry.hpp"
#include "vines/hal/deadline.hpp"
#include "vines/hal/link_protocol.hpp"
#include "vines/hal/port.hpp"
#include "vines/sim.hpp"

// Eigen's data layout is the same on every target (host x86-64 with SSE2 or
// AVX2, Cortex-M without SIMD): fixed-size objects 16-byte aligned.
static_assert(EIGEN_MAX_STATIC_ALIGN_BYTES == 16, "Eigen alignment differs from the other targets");

namespace {

using Scalar = VINES_APP_SCALAR;
constexpr int kStories = 10;
#if VINES_APP_DEVICE == 1
using Dev = vines::TmdDevice;
constexpr const char* kDeviceName = "tmd";
#elif VINES_APP_DEVICE == 2
using Dev = vines::VinesDevice<vines::ContactLaw::kKuwabara>;
constexpr const char* kDeviceName = "vines (Kuwabara)";
#else
#error "VINES_APP_DEVICE must be 1 (tmd) or 2 (vines, Kuwabara)"
#endif

// Static blocks: the models and the run's data never live on the stack.
vines::Model<Scalar, kStories, Dev> g_model;
vines::Data<Scalar, kStories, Dev> g_data;
vines::Model<Scalar, kStories, vines::NoDevice> g_bare_model;
vines::Data<Scalar, kStories, vines::NoDevice> g_bare;
vines::SceneParams g_params;

int refuse(const char* what, const char* detail = "") {
  vines::hal::console_write("vines loop: ");
  vines::hal::console_write(what);
  vines::hal::console_write(detail);
  vines::hal::console_write("\n");
  vines::app::put("error\n");
  return 1;
}

int refuse_params(const vines::ParamError& e) {
  vines::hal::console_write("vines loop: scene refused: ");
  vines::hal::console_write(e.field);
  vines::hal::console_write(": ");
  return refuse(e.message);
}

// Reads and checks the header and the scene.
int configure(vines::hal::link::Header* h) {
  namespace link = vines::hal::link;
  if (!vines::hal::link_read(h, sizeof *h)) return refuse("no header on the link: ", vines::hal::port_error());
  for (int i = 0; i < 4; ++i)
    if (h->magic[i] != link::kMagic[i]) return refuse("the link does not start with VNS1 (not a vines_feed stream)");
  if (h->params_bytes != sizeof(vines::SceneParams) || h->params_layout != link::layout_check())
    return refuse("the scene's layout differs from this image's (feed and image built from other sources)");
  if (h->sample_bytes != sizeof(Scalar))
    return refuse(sizeof(Scalar) == 4 ? "this image runs in float: feed it with --scalar float"
                                      : "this image runs in double: feed it with --scalar double");
  if (h->samples < 2) return refuse("fewer than 2 samples: nothing to step");
  if (!vines::hal::link_read(&g_params, sizeof g_params)) return refuse("scene cut short: ", vines::hal::port_error());
  const vines::SceneParams& p = g_params;
  if (p.frame.stories != kStories) return refuse("this image is built for 10 stories");
  if (p.device.kind != Dev::kKind ||
      (Dev::kKind == vines::DeviceKind::kVines && p.device.vines.law != vines::ContactLaw::kKuwabara))
    return refuse("the scene's device is not this image's: ", kDeviceName);
  vines::ParamError e = vines::build_model(p, &g_model);
  if (!e.ok()) return refuse_params(e);
  vines::SceneParams bare = p;
  bare.device.kind = vines::DeviceKind::kNone;
  e = vines::build_model(bare, &g_bare_model);
  if (!e.ok()) return refuse_params(e);
  return 0;
}

void report(const vines::hal::DeadlineMonitor& monitor) {
  using vines::app::put_double;
  using vines::app::put_int;
  const auto& d = g_data;
  const auto& b = g_bare;
  const double peak = static_cast<double>(d.peak_top), bare_peak = static_cast<double>(b.peak_top);
  put_double("peak_top_displacement_m", peak);
  put_double("t_peak_top_s", d.t_peak_top);
  const double ee = vines::elastic_energy(g_model, d), bare_ee = vines::elastic_energy(g_bare_model, b);
  put_double("elastic_energy_integral", ee);
  put_double("bare_peak_top_displacement_m", bare_peak);
  put_double("bare_elastic_energy_integral", bare_ee);
  put_double("x_r", (bare_peak - peak) / bare_peak);
  put_double("E_r", (bare_ee - ee) / bare_ee);
  if (g_params.loop.energy_ledger) put_double("energy_balance_residual", d.ledger.relative_residual());
  if constexpr (Dev::kKind == vines::DeviceKind::kVines) put_double("max_overlap_m", static_cast<double>(d.max_overlap));
  put_int("contacts", d.count.contacts);
  put_int("steps", d.count.steps);
  put_int("substep_steps", d.count.careful_steps);
  put_int("divergences", d.count.divergences);
  put_int("deadline_budget_ticks", monitor.budget());
  put_int("deadline_overruns", monitor.overruns());
  put_int("deadline_worst_ticks", monitor.worst());
  put_int("ticks_missed", vines::hal::ticks_missed());
  put_int("counter_hz", vines::hal::counter_hz());
  put_int("stack_peak_bytes", vines::hal::stack_peak_bytes());
  vines::app::put("end\n");
}

}  // namespace

int main() {
  vines::hal::stack_paint();
  vines::hal::port_init();
  vines::hal::link::Header h{};
  if (const int rc = configure(&h)) return rc;
  const double rate = g_params.loop.sensor_rate_hz;
  vines::app::LinkSource source(rate, h.samples, h.sample_bytes);
  const std::uint32_t period = static_cast<std::uint32_t>(vines::hal::counter_hz() / rate + 0.5);
  vines::hal::DeadlineMonitor monitor(h.budget_ticks ? h.budget_ticks : period);
  if (!vines::hal::tick_start(rate)) return refuse("the sensor rate is out of the tick timer's range");

  double a = 0.0;
  if (!source.next(&a)) return refuse("no first sample: ", vines::hal::port_error());
  vines::init(g_model, g_data, static_cast<Scalar>(a));
  vines::init(g_bare_model, g_bare, static_cast<Scalar>(a));
  while (true) {
    vines::hal::wait_tick();
    if (!source.next(&a)) break;
    const auto careful_before = g_data.count.careful_steps;
    vines::hal::irq_off();
    const std::uint32_t t0 = vines::hal::counter_now();
    vines::step(g_model, g_data, static_cast<Scalar>(a));
    const std::uint32_t ticks = vines::hal::counter_now() - t0;
    vines::hal::irq_on();
    monitor.record(ticks);
    vines::step(g_bare_model, g_bare, static_cast<Scalar>(a));
    vines::app::put(g_data.count.careful_steps != careful_before ? "c " : "f ");
    vines::app::put_uint(ticks);
    vines::app::put("\n");
  }
  if (source.failed()) return refuse("samples cut short: ", vines::hal::port_error());
  report(monitor);
  return 0;
}
