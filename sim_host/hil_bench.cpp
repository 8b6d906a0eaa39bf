#include "sim_host/hil_bench.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/hil_offline.hpp"
#include "vines/contact_laws.hpp"

namespace vines::host {
namespace {

// "hertz, tsuji or kuwabara": the laws of finite contact duration, from the
// registry (vines/contact_laws.hpp).
std::string finite_laws() {
  std::vector<std::string> names;
  each_law([&](auto law) {
    if (!decltype(law)::kImpulsive) names.emplace_back(decltype(law)::kName);
  });
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}

constexpr link::NodeMode kNodeModes[] = {link::NodeMode::kReplay, link::NodeMode::kTwin, link::NodeMode::kHybrid};

// The node: the host's `vines node` or a board in QEMU (its image, scalar and
// a longer timeout).
void choose_node(Bench* b) {
  HilOptions& o = b->opt;
  const std::string refused = "--node " + o.node + ": must be host, qemu:cortex-m4f or qemu:cortex-m7";
  if (o.node.rfind("qemu:", 0) == 0) {
    b->board = board_of(o.node);
    if (!b->board) throw std::runtime_error(refused);
    if (o.realtime)
      throw std::runtime_error("--node " + o.node + ": QEMU counts instructions, not wall time: use the virtual clock");
    o.image = board_image(o, *b->board, b->scene);
    if (o.timeout_s <= 0) o.timeout_s = 60;  // QEMU boots, and takes ~20 kB/s
    b->scene.scalar = b->board->scalar;      // the board's scalar, whatever the scene says
  } else if (o.node != "host") {
    throw std::runtime_error(refused);
  }
  if (o.timeout_s <= 0) o.timeout_s = 5;
}

link::NodeConfig node_config(const Scene& scene, const HilOptions& opt) {
  link::NodeConfig c;
  c.scene = scene.params;
  c.scalar = scene.scalar == Scalar::kFloat ? 1 : 0;
  c.mode = kNodeModes[static_cast<int>(opt.mode)];
  c.sensor_range_mps2 = opt.saturate_g * kGravity;
  c.grace_periods = opt.grace_periods;
  c.stall_periods = opt.node_stall_periods;
  for (int i = 0; i < scene.params.frame.stories; ++i) c.drift_limit_m[i] = opt.drift_limit_m;
  c.residual_limit_mps2 = opt.residual_limit_mps2;
  c.residual_window_s = opt.residual_window_s;
  c.comp_delay_s = opt.comp_delay_s;
  c.comp_order = static_cast<std::uint8_t>(opt.comp_order);
  c.budget_ticks = opt.budget_ticks;
  if (const char* why = link::validate_node(c)) throw std::runtime_error(why);
  return c;
}

}  // namespace

Bench make_bench(const Scene& scene, const HilOptions& opt) {
  Bench b;
  b.scene = scene;
  b.opt = opt;
  if (opt.duration_s > 0) b.scene.duration_s = opt.duration_s;
  choose_node(&b);
  const Scene& sc = b.scene;
  b.ex = load_excitation(sc, "");
  b.samples = static_cast<long long>(b.ex.samples.size());
  b.h = 1.0 / sc.params.loop.sensor_rate_hz;
  // Hybrid: the table's load cell measures contact forces, and the command
  // is compensated by default for the actuator's delay and lag (2 zeta / w).
  HilOptions& o = b.opt;
  const bool hybrid = o.mode == HilMode::kHybrid;
  if (hybrid && (sc.params.device.kind != DeviceKind::kVines || law_impulsive(sc.params.device.vines.law)))
    throw std::runtime_error(sc.path + ": --mode hybrid needs a VI NES scene with a finite-duration contact law (" +
                             finite_laws() + "): the table's load cell measures contact forces");
  if (hybrid && o.comp_delay_s < 0) o.comp_delay_s = o.actuator_delay_s + 2 * o.actuator_zeta / (2 * M_PI * o.actuator_hz);
  if (o.comp_delay_s < 0) o.comp_delay_s = 0;
  b.cfg = node_config(sc, o);
  b.image = model_image(b.cfg, sc.path);
  return b;
}

}  // namespace vines::host
