#include "sim_host/hil/bench.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/engines/build_engine.hpp"
#include "sim_host/hil/link/serial.hpp"
#include "sim_host/hil/link/tcp.hpp"
#include "sim_host/hil/offline.hpp"
#include "vines/link/ats.hpp"
#include "vines/link/frame.hpp"
#include "vines/link/messages.hpp"
#include "vines/model/contact_laws.hpp"

namespace vines::host {
namespace {

// "hertz, tsuji or kuwabara": the laws of finite contact duration, from the
// registry (vines/model/contact_laws.hpp).
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

// The scene's device as the hybrid mode's specimen: a TMD or a VI NES of a
// finite-duration law, on the top floor (the table plays it).
void check_specimen(const Scene& sc) {
  const DeviceParams& d = sc.params.device;
  const int n = sc.params.frame.stories;
  if (d.kind == DeviceKind::kNone)
    throw std::runtime_error(sc.path + ": --mode hybrid needs a device on the table (device.kind tmd or vines)");
  if (d.kind == DeviceKind::kVines && law_impulsive(d.vines.law))
    throw std::runtime_error(sc.path + ": --mode hybrid needs a VI NES scene with a finite-duration contact law (" +
                             finite_laws() + "): the table's load cell measures contact forces");
  if (d.floor != 0 && d.floor != n)
    throw std::runtime_error(sc.path + ": --mode hybrid: device.floor " + std::to_string(d.floor) +
                             ": the table plays the top floor (0 or " + std::to_string(n) + ")");
}

// Another mode's options are refused, not ignored.
void check_mode_options(const HilOptions& o) {
  const HilOptions d;
  if (o.mode != HilMode::kTwin) {
    const char* given = !o.truth_path.empty()                        ? "--truth"
                        : !o.sensors.empty()                         ? "--sensors"
                        : o.measure_noise_mps2 != d.measure_noise_mps2 ? "--measure-noise"
                        : o.measure_noise_pct != d.measure_noise_pct ? "--measure-noise-pct"
                        : o.measure_bias_mps2 != d.measure_bias_mps2 ? "--measure-bias"
                        : o.adc_lsb_mps2 != d.adc_lsb_mps2           ? "--adc-lsb"
                        : o.truth_stiffness_scale != d.truth_stiffness_scale ? "--truth-stiffness-scale"
                                                                             : nullptr;
    if (given) throw std::runtime_error(std::string(given) + ": a twin option (--mode twin)");
  }
}

// --floors: floors of the scene's frame, each once (a column each).
void check_floors(const HilOptions& o, const Scene& sc) {
  const int n = sc.params.frame.stories;
  for (std::size_t i = 0; i < o.floors.size(); ++i) {
    const int f = o.floors[i];
    if (f < 1 || f > n)
      throw std::runtime_error("--floors " + std::to_string(f) + ": " + sc.path + " has floors 1 to " + std::to_string(n));
    for (std::size_t j = 0; j < i; ++j)
      if (o.floors[j] == f) throw std::runtime_error("--floors " + std::to_string(f) + ": given twice");
  }
}

constexpr link::NodeMode kNodeModes[] = {link::NodeMode::kReplay, link::NodeMode::kTwin, link::NodeMode::kHybrid};

// The node: the host's `vines node` or a board in QEMU (its image, scalar and
// a longer timeout).
void choose_node(Bench* b) {
  HilOptions& o = b->opt;
  const std::string refused = "--node " + o.node + ": must be " + node_list();
  if (o.node.rfind("qemu:", 0) == 0) {
    b->board = board_of(o.node);
    if (!b->board) throw std::runtime_error(refused);
    if (o.realtime)
      throw std::runtime_error("--node " + o.node + ": QEMU counts instructions, not wall time: use the virtual clock");
    o.image = board_image(o, *b->board, b->scene);
    if (o.timeout_s <= 0) o.timeout_s = 60;  // QEMU boots, and takes ~20 kB/s
    b->scene.scalar = b->board->scalar;      // the board's scalar, whatever the scene says
  } else if (is_tcp(o.node)) {
    parse_tcp_address(o.node, "", false);  // throws naming what is wrong
  } else if (is_serial(o.node)) {
    parse_serial_address(o.node);
    if (o.faults[static_cast<int>(FaultKind::kRestart)].any())
      throw std::runtime_error("--restart: the bench cannot cut the power of a node on a serial line (" + o.node +
                               "); inject it with a pipe, QEMU or TCP node");
  } else if (o.node != "host") {
    throw std::runtime_error(refused);
  }
  if ((o.rt_priority > 0 || !o.cpus.empty()) && !o.realtime)
    throw std::runtime_error(std::string(o.rt_priority > 0 ? "--realtime-priority" : "--cpus") +
                             ": real-time service is for a run on the wall clock: add --realtime");
  if (o.cpus.size() > 2) throw std::runtime_error("--cpus: B[,N], the bench's core and the host node's");
  if (o.timeout_s <= 0) o.timeout_s = 5;
}

link::NodeConfig node_config(const Scene& scene, const HilOptions& opt) {
  link::NodeConfig c;
  c.scene = scene.params;
  c.scalar = link_code(scene.scalar);
  c.mode = kNodeModes[static_cast<int>(opt.mode)];
  c.sensor_range_mps2 = opt.saturate_g * kGravity;
  c.grace_periods = opt.grace_periods;
  c.stall_periods = opt.node_stall_periods;
  for (int i = 0; i < scene.params.frame.stories; ++i) c.drift_limit_m[i] = opt.drift_limit_m;
  c.residual_limit_mps2 = opt.residual_limit_mps2;
  c.residual_window_s = opt.residual_window_s;
  if (opt.mode == HilMode::kTwin && opt.estimator == HilEstimator::kKalman) c.estimator = link::TwinEstimator::kKalman;
  constexpr link::CompKind kinds[] = {link::CompKind::kNone, link::CompKind::kPolynomial, link::CompKind::kAdaptive};
  c.comp_kind = kinds[static_cast<int>(opt.comp)];
  c.comp_delay_s = opt.comp_delay_s;
  c.comp_order = static_cast<std::uint8_t>(opt.comp_order);
  c.comp_window_s = opt.comp_window_s;
  c.budget_ticks = opt.budget_ticks;
  if (const char* why = link::validate_node(c)) throw std::runtime_error(why);
  return c;
}

// A frame's bytes on the wire at most: COBS's overhead and the delimiter.
template <class Msg>
std::size_t wire_bytes(const Msg& m) {
  std::uint8_t payload[link::kMaxPayload];
  return link::cobs_max_encoded(link::kHeaderBytes + link::encode(m, payload, sizeof payload) + link::kCrcBytes) + 1;
}

// A node on a serial line: the samples' frames and the telemetry's must fit
// the line at the sensor rate (lock step or real time alike).
void check_serial_line(const Bench& b) {
  if (!is_serial(b.opt.node)) return;
  link::Sample s;
  s.ny = static_cast<std::uint8_t>(b.cfg.estimator == link::TwinEstimator::kKalman ? b.twin.sensors.size() : 0);
  link::Telemetry t;
  t.n = static_cast<std::uint8_t>(b.scene.params.frame.stories);
  check_line_rate(parse_serial_address(b.opt.node), 1.0 / b.h, wire_bytes(s), wire_bytes(t));
}

}  // namespace

Bench make_bench(const Scene& scene, const HilOptions& opt) {
  Bench b;
  b.scene = scene;
  b.opt = opt;
  if (opt.duration_s > 0) b.scene.duration_s = opt.duration_s;
  // The node runs its scene's model: damage belongs to the twin's truth.
  if (opt.mode != HilMode::kTwin) refuse_damage(scene, "vines hil (the node's scene)");
  choose_node(&b);
  const Scene& sc = b.scene;
  b.ex = load_excitation(sc, "");
  b.samples = static_cast<long long>(b.ex.samples.size());
  b.h = 1.0 / sc.params.loop.sensor_rate_hz;
  // Hybrid: the table carries the device and plays the top floor; its load
  // cell measures forces (a VI NES's contacts must last), and the command is
  // compensated by default for the actuator's delay, its lag (2 zeta / w)
  // and the command's hold over a period (h / 2).
  HilOptions& o = b.opt;
  const bool hybrid = o.mode == HilMode::kHybrid;
  check_mode_options(o);
  check_floors(opt, scene);
  if (hybrid) check_specimen(sc);
  if (hybrid && o.comp_delay_s < 0)
    o.comp_delay_s = o.actuator_delay_s + 2 * o.actuator_zeta / (2 * M_PI * o.actuator_hz) + 0.5 * b.h;
  if (o.comp_delay_s < 0 || o.comp == HilComp::kNone) o.comp_delay_s = 0;
  if (hybrid && o.comp == HilComp::kAdaptive && o.comp_delay_s > link::kAtsHigh[1]) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "--comp-delay %.4g s (given, or the actuator's delay and lag): --comp adaptive starts a1 there, "
                  "which must be 0 to %g s",
                  o.comp_delay_s, link::kAtsHigh[1]);
    throw std::runtime_error(why);
  }
  b.cfg = node_config(sc, o);
  if (o.mode == HilMode::kTwin) b.twin = make_twin_bench(sc, o, b.ex);
  b.image = b.cfg.estimator == link::TwinEstimator::kKalman ? b.twin.design.image : model_image(b.cfg, sc.path);
  check_serial_line(b);
  return b;
}

DeviceLayout device_layout(const Scene& scene) {
  const DeviceKind kind = scene.params.device.kind;
  DeviceLayout d;
  if (kind == DeviceKind::kNone) return d;
  const ModelInfo info = build_engine(scene.params, scene.scalar, scene.path)->info();
  d.kind = kind == DeviceKind::kTmd ? "tmd" : "vines";
  d.floor = info.device_floor;
  if (kind == DeviceKind::kVines) d.gap_m = info.vines.gap;
  return d;
}

}  // namespace vines::host
