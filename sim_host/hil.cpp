#include "sim_host/hil.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>

#include "sim_host/hil_boards.hpp"
#include "sim_host/hil_faults.hpp"
#include "sim_host/hil_lab.hpp"
#include "sim_host/hil_link.hpp"
#include "sim_host/hil_offline.hpp"
#include "sim_host/run.hpp"
#include "vines/link/config.hpp"
#include "vines/link/frame.hpp"
#include "vines/link/messages.hpp"

namespace vines::host {
namespace {

using nlohmann::json;
using Clock = HilClock;
using link::Telemetry;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The replay-mode comparison: every field the telemetry shares with the run.
bool equal_outputs(const Telemetry& a, const Telemetry& b) {
  if (a.n != b.n || a.contact_mode != b.contact_mode) return false;
  for (int i = 0; i < a.n; ++i)
    if (!same_bits(a.x[i], b.x[i])) return false;
  return same_bits(a.acc_top, b.acc_top) && same_bits(a.elastic_energy, b.elastic_energy) &&
         same_bits(a.particle_x, b.particle_x) && same_bits(a.particle_v, b.particle_v) &&
         same_bits(a.contact_force, b.contact_force) && same_bits(a.dissipated, b.dissipated);
}

constexpr link::NodeMode kNodeModes[] = {link::NodeMode::kReplay, link::NodeMode::kTwin, link::NodeMode::kHybrid};

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

json stats(std::vector<double> v) {
  if (v.empty()) return nullptr;
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  auto q = [&](double p) { return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))]; };
  return {{"mean", sum / static_cast<double>(v.size())}, {"p50", q(0.5)}, {"p99", q(0.99)}, {"max", v.back()}};
}

}  // namespace

json run_hil(const Scene& scene, const HilOptions& opt) {
  Scene sc = scene;
  if (opt.duration_s > 0) sc.duration_s = opt.duration_s;
  HilOptions o = opt;
  const Board* board = nullptr;
  if (o.node.rfind("qemu:", 0) == 0) {
    board = board_of(o.node);
    if (!board) throw std::runtime_error("--node " + o.node + ": must be host, qemu:cortex-m4f or qemu:cortex-m7");
    if (o.mode == HilMode::kHybrid)
      throw std::runtime_error("--node " + o.node + ": hybrid mode runs on the host node only");
    if (o.realtime)
      throw std::runtime_error("--node " + o.node + ": QEMU counts instructions, not wall time: use the virtual clock");
    o.image = board_image(o, *board, sc);
    if (o.timeout_s <= 0) o.timeout_s = 60;  // QEMU boots, and takes ~20 kB/s
    sc.scalar = board->scalar;  // the board's scalar, whatever the scene says
  } else if (o.node != "host") {
    throw std::runtime_error("--node " + o.node + ": must be host, qemu:cortex-m4f or qemu:cortex-m7");
  }
  if (o.timeout_s <= 0) o.timeout_s = 5;
  const Excitation ex = load_excitation(sc, "");
  const long long K = static_cast<long long>(ex.samples.size());
  const double h = 1.0 / sc.params.loop.sensor_rate_hz;
  const bool hybrid = opt.mode == HilMode::kHybrid, twin = opt.mode == HilMode::kTwin;
  if (hybrid && (sc.params.device.kind != DeviceKind::kVines || sc.params.device.vines.law == ContactLaw::kRestitution))
    throw std::runtime_error(sc.path + ": --mode hybrid needs a VI NES scene with a finite-duration contact law "
                             "(hertz, tsuji or kuwabara): the table's load cell measures contact forces");

  if (hybrid && o.comp_delay_s < 0) o.comp_delay_s = o.actuator_delay_s + 2 * o.actuator_zeta / (2 * M_PI * o.actuator_hz);
  if (o.comp_delay_s < 0) o.comp_delay_s = 0;
  const link::NodeConfig cfg = node_config(sc, o);
  const std::vector<std::uint8_t> image = model_image(cfg, sc.path);

  // What the node's telemetry is compared with: the offline run of the scene
  // (hybrid: the pure simulation, the device in the model).
  link::NodeConfig off_cfg = cfg;
  off_cfg.mode = link::NodeMode::kReplay;
  const std::vector<Telemetry> offline = offline_run(off_cfg, ex.samples, sc.path);
  // Twin: the measured building (stiffness scaled by eta_k).
  std::vector<double> measured;
  if (twin) {
    link::NodeConfig truth = off_cfg;
    truth.scene.frame.stiffness_scale *= o.truth_stiffness_scale;
    const std::vector<Telemetry> t = offline_run(truth, ex.samples, "--truth-stiffness-scale");
    std::mt19937_64 rng(o.seed + 17);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (const Telemetry& r : t) measured.push_back(r.acc_top + o.measure_noise_mps2 * noise(rng));
  }
  std::unique_ptr<ShakeTable> lab;
  if (hybrid) {
    std::unique_ptr<Engine> eng = make_engine(sc.params, sc.scalar);  // built fine by offline_run
    eng->build(sc.params);
    LabOptions lo{o.actuator_hz, o.actuator_zeta, o.actuator_delay_s, o.force_noise_n, o.force_lsb_n, o.seed};
    lab = std::make_unique<ShakeTable>(eng->info().vines, sc.params.device.vines.law, offline[0].particle_x,
                                       offline[0].particle_v, h, lo);
  }

  // The samples as the sensor gives them (clipped at its range).
  std::vector<double> sensed = ex.samples;
  std::vector<char> clipped(static_cast<std::size_t>(K), 0);
  const double range = cfg.sensor_range_mps2;
  if (range > 0)
    for (long long k = 0; k < K; ++k)
      if (std::fabs(sensed[k]) >= range) sensed[k] = std::copysign(range, sensed[k]), clipped[k] = 1;

  std::vector<FaultEvent> events = plan_faults(o, K);
  std::vector<FaultEvent*> at(static_cast<std::size_t>(K), nullptr);
  for (FaultEvent& e : events) at[static_cast<std::size_t>(e.k)] = &e;

  // Telemetry by step, its arrival (bench clock, s) and latency.
  std::vector<Telemetry> tel(static_cast<std::size_t>(K));
  std::vector<char> got(static_cast<std::size_t>(K), 0);
  std::vector<double> arrival(static_cast<std::size_t>(K), 0), handled(static_cast<std::size_t>(K), 0);
  std::vector<link::Fault> faults;
  std::vector<long long> fault_life;
  std::vector<double> force(static_cast<std::size_t>(K), 0), table_x(static_cast<std::size_t>(K), 0),
      command_used(static_cast<std::size_t>(K), 0);
  long long bad_frames = 0, life = 0;
  double last_command = 0;

  auto t0 = Clock::now();
  auto node = std::make_unique<NodeLink>(o, life, &faults, &fault_life);
  auto attach = [&](NodeLink& n) {
    n.set_epoch(t0);
    n.on_telemetry = [&](const Telemetry& t, double now) {
      if (t.k >= static_cast<std::uint32_t>(K)) return;
      tel[t.k] = t;
      got[t.k] = 1;
      arrival[t.k] = now;
      if (hybrid) last_command = t.aux;
    };
  };
  attach(*node);
  configure(*node, cfg, image);
  t0 = Clock::now();  // the bench clock starts with the run
  node->set_epoch(t0);
  start(*node, 0, 0);

  const auto sample_frame = [&](long long k, double now_s) {
    link::Sample s;
    s.k = static_cast<std::uint32_t>(k);
    s.t_ns = static_cast<std::uint64_t>(std::llround(now_s * 1e9));
    s.ag = sensed[k];
    s.aux = twin ? measured[k] : hybrid ? force[k] : 0.0;
    const FaultEvent* e = at[static_cast<std::size_t>(k)];
    if (e && e->kind == FaultKind::kNonFinite) s.ag = k % 2 ? std::numeric_limits<double>::infinity() : std::nan("");
    return node->encode(link::MsgType::kSample, s);
  };
  // Virtual clock: the node's clock is the samples' stamps, so a few frames
  // may be under way at once without changing what it computes. A board in
  // QEMU takes a byte per turn of QEMU's loop: a window of frames keeps its
  // UART busy; the host node runs in strict lock step (its latency is
  // measured per sample).
  const std::uint32_t in_flight = board ? 16 : 0;
  std::multimap<long long, long long> releases;  // release at sample -> sample
  std::vector<std::uint8_t> reordered;            // frame held back by a reorder
  long long reordered_k = -1;
  std::mt19937_64 rng(o.seed + 5);

  for (long long k = 0; k < K; ++k) {
    const double due = static_cast<double>(k) * h;
    if (o.realtime) {
      // Read until the sample is due, then send it.
      for (double left = due - seconds_since(t0); left > 0; left = due - seconds_since(t0)) node->pump(std::min(left, 0.002));
    }
    const double now = o.realtime ? seconds_since(t0) : due;
    handled[k] = seconds_since(t0);
    FaultEvent* e = at[static_cast<std::size_t>(k)];
    if (e) e->life = life;
    if (e && e->kind == FaultKind::kRestart) {
      bad_frames += node->bad_frames();
      node->kill();
      node = std::make_unique<NodeLink>(o, ++life, &faults, &fault_life);
      attach(*node);
      configure(*node, cfg, image);
      // The restarted node's clock starts where the bench's is: the wall
      // clock in real time, the sample's due time on the virtual clock (the
      // wall time there would make it hold every step up to it).
      start(*node, k, static_cast<std::uint64_t>(std::llround((o.realtime ? seconds_since(t0) : due) * 1e9)));
      e->life = life;
      e->detected = node->first_cold_start();
    }
    if (hybrid) {
      // The lab: the table follows the last command received; the load cell
      // reads the specimen at the sample instant.
      command_used[k] = last_command;
      force[k] = k == 0 ? 0.0 : lab->advance(last_command, ex.samples[k - 1], ex.samples[k]);
      table_x[k] = lab->table_x();
    }
    for (auto r = releases.lower_bound(k); r != releases.end() && r->first == k; r = releases.erase(r))
      node->send(sample_frame(r->second, now));
    if (!reordered.empty() && k == reordered_k + 1) {
      node->send(sample_frame(k, now));
      node->send(reordered);
      reordered.clear();
    } else if (e && e->kind == FaultKind::kStall) {
      for (long long j = k; j < k + e->span; ++j) releases.emplace(k + e->span, j);
    } else if (e && e->kind == FaultKind::kLate) {
      releases.emplace(k + e->span, k);
    } else if (!(releases.size() && std::any_of(releases.begin(), releases.end(), [&](auto& r) { return r.second == k; }))) {
      const unsigned seq = node->next_seq();
      std::vector<std::uint8_t> f = sample_frame(k, now);
      const FaultKind kind = e ? e->kind : FaultKind::kCount;
      if (e && (kind == FaultKind::kDrop || kind == FaultKind::kCorrupt || kind == FaultKind::kDuplicate ||
                kind == FaultKind::kReorder))
        e->seqs.push_back(seq);
      if (kind == FaultKind::kCorrupt) {
        f[rng() % (f.size() - 1)] ^= static_cast<std::uint8_t>(1 + rng() % 255);
      }
      if (kind == FaultKind::kReorder) {
        reordered = f;
        reordered_k = k;
      } else if (kind != FaultKind::kDrop) {
        node->send(f);
        if (kind == FaultKind::kDuplicate) node->send(f);
      }
    }
    if (!o.realtime) node->wait_answered(in_flight);
  }
  for (auto& r : releases) node->send(sample_frame(r.second, static_cast<double>(K) * h));
  node->send(node->encode_empty(link::MsgType::kStop));
  node->wait_answered();
  const link::Status final_status = node->status();
  bad_frames += node->bad_frames();
  const int node_exit = node->finish();
  const double wall = seconds_since(t0);

  // ---- detection and survival ----
  std::map<std::string, std::array<long long, 3>> per_kind;  // injected, detected, survived
  auto fault_seen = [&](const FaultEvent& e, link::FaultCode code, long long lo, long long hi) {
    for (std::size_t i = 0; i < faults.size(); ++i)
      if (fault_life[i] == e.life && faults[i].code == code && faults[i].k >= lo && faults[i].k <= hi) return true;
    return false;
  };
  auto seq_missing = [&](const FaultEvent& e) {
    for (unsigned s : e.seqs)
      for (std::size_t i = 0; i < faults.size(); ++i)
        if (fault_life[i] == e.life && faults[i].code == link::FaultCode::kSeqGap &&
            static_cast<std::uint16_t>(s - faults[i].k) < faults[i].count)
          return true;
    return false;
  };
  auto finite = [&](const Telemetry& t) {
    for (int i = 0; i < t.n; ++i)
      if (!(std::fabs(t.x[i]) < sc.params.loop.divergence_limit_m)) return false;
    return std::isfinite(t.acc_top) && std::isfinite(t.aux);
  };
  for (FaultEvent& e : events) {
    const unsigned s0 = e.seqs.empty() ? 0 : e.seqs[0];
    switch (e.kind) {
      case FaultKind::kDrop:
      case FaultKind::kCorrupt: e.detected = seq_missing(e); break;
      case FaultKind::kDuplicate: e.detected = fault_seen(e, link::FaultCode::kDuplicate, s0, s0); break;
      case FaultKind::kReorder: e.detected = fault_seen(e, link::FaultCode::kReordered, s0, s0); break;
      case FaultKind::kLate: e.detected = fault_seen(e, link::FaultCode::kLate, e.k, e.k); break;
      case FaultKind::kNonFinite: e.detected = fault_seen(e, link::FaultCode::kNonFinite, e.k, e.k); break;
      case FaultKind::kStall: e.detected = fault_seen(e, link::FaultCode::kStall, e.k, e.k + e.span); break;
      default: break;
    }
    e.survived = true;
    const long long from = e.k + e.span + 1, to = std::min(K - 1, from + 10);
    for (long long j = from; j <= to; ++j) e.survived = e.survived && got[j] && finite(tel[j]);
    auto& c = per_kind[fault_kind_name(e.kind)];
    c[0] += 1, c[1] += e.detected, c[2] += e.survived;
  }
  // Saturation counts on samples that reach the node on time and intact and
  // that it stepped (a clipped sample that is also dropped, late, ... is that
  // other fault; one in flight when its node was killed never arrived). The
  // node sends a step's faults before its telemetry, on one ordered stream.
  for (const FaultEvent& e : events)
    for (long long j = e.k; j < e.k + (e.kind == FaultKind::kStall ? e.span : 1); ++j) clipped[j] = 0;
  long long clipped_n = 0, clipped_seen = 0;
  for (long long k = 0; k < K; ++k) clipped_n += clipped[k] && got[k];
  for (const link::Fault& f : faults) clipped_seen += f.code == link::FaultCode::kSaturated && f.k < K && clipped[f.k] && got[f.k];
  if (clipped_n > 0) {
    long long survived = 1;
    for (long long k = 0; k < K; ++k) survived &= !got[k] || finite(tel[k]);
    per_kind["saturate"] = {clipped_n, clipped_seen, survived ? clipped_n : 0};
  }

  // ---- deadlines, deviation ----
  long long steps = 0, misses = 0, missing = 0;
  bool exact = true, all_finite = true;
  double max_dev = 0, max_x = 0;
  std::vector<double> latency_us;
  const double deadline = o.deadline_periods * h;
  const int n = sc.params.frame.stories;
  for (long long k = 0; k < K; ++k) {
    if (!got[k]) {
      ++missing, ++misses;
      continue;
    }
    ++steps;
    const Telemetry& t = tel[k];
    // Real time: telemetry due by the sample's time plus the deadline; virtual
    // clock: its latency (sample handled to telemetry back) within the deadline.
    const double late = o.realtime ? arrival[k] - static_cast<double>(k) * h : arrival[k] - handled[k];
    latency_us.push_back(1e6 * (arrival[k] - handled[k]));
    // A board in QEMU keeps the board's time, not the host's: its deadline is
    // the step's cost on its counter against the budget (one period).
    if (board ? tel[k].step_ticks > final_status.timing.budget_ticks : late > deadline) ++misses;
    all_finite = all_finite && finite(t);
    for (int i = 0; i < n; ++i) {
      max_dev = std::max(max_dev, std::fabs(t.x[i] - offline[k].x[i]));
      max_x = std::max(max_x, std::fabs(t.x[i]));
    }
    exact = exact && equal_outputs(t, offline[k]);
  }
  if (!all_finite) max_dev = std::numeric_limits<double>::infinity();

  long long injected = 0, detected = 0, survived = 0;
  json kinds = json::object();
  for (auto& [name, c] : per_kind) {
    kinds[name] = {{"injected", c[0]}, {"detected", c[1]}, {"survived", c[2]}};
    injected += c[0], detected += c[1], survived += c[2];
  }
  json node_faults = json::object();
  for (int c = 0; c < link::kFaultCodes; ++c) {
    long long count = 0;
    for (const link::Fault& f : faults) count += static_cast<int>(f.code) == c;
    if (count) node_faults[link::fault_name(static_cast<link::FaultCode>(c))] = count;
  }

  json j;
  j["scene"] = sc.name;
  j["mode"] = hil_mode_name(o.mode);
  j["clock"] = o.realtime ? "realtime" : "virtual";
  j["scalar"] = scalar_name(sc.scalar);
  j["sensor_rate_hz"] = sc.params.loop.sensor_rate_hz;
  j["samples"] = K;
  j["steps"] = steps;
  j["missing_steps"] = missing;
  j["deadline_s"] = board && final_status.timing.counter_hz
                       ? static_cast<double>(final_status.timing.budget_ticks) / final_status.timing.counter_hz
                       : deadline;
  j["deadline_misses"] = misses;
  j["latency_us"] = stats(latency_us);
  j["faults_injected"] = injected;
  j["faults_detected"] = detected;
  j["faults_survived"] = survived;
  j["faults"] = kinds;
  j["node_faults"] = node_faults;
  j["node_restarts"] = life;
  j["bad_frames_from_node"] = bad_frames;
  j["max_deviation_from_offline"] = max_dev;
  j["bit_exact"] = exact && missing == 0 && !hybrid;
  j["outputs_finite"] = all_finite;
  j["max_abs_floor_displacement_m"] = max_x;
  j["node_status"] = {{"steps", final_status.steps}, {"state", static_cast<int>(final_status.state)},
                      {"exit_status", node_exit}};
  // The node's deadline monitor (its counter: ns on the host, the 25 MHz
  // timer on a board) and each step's cost from telemetry.
  const link::StepTiming& tm = final_status.timing;
  j["node"] = o.node;
  j["node_deadline"] = {{"counter_hz", tm.counter_hz},   {"budget_ticks", tm.budget_ticks},
                        {"overruns", tm.overruns},       {"worst_ticks", tm.worst_ticks},
                        {"worst_k", tm.worst_k},         {"stack_peak_bytes", tm.stack_peak_bytes}};
  std::vector<double> ticks;
  long long over = 0;
  for (long long k = 0; k < K; ++k)
    if (got[k]) ticks.push_back(tel[k].step_ticks), over += tel[k].step_ticks > tm.budget_ticks;
  j["step_ticks"] = stats(ticks);
  j["steps_over_budget"] = over;  // from telemetry: equals the monitor's overruns on a clean run
  if (board && !ticks.empty()) {
    std::sort(ticks.begin(), ticks.end());
    j["icount_shift"] = kIcountShift;
    j["worst_step_instructions"] = kInstructionsPerTick * tm.worst_ticks;
    j["worst_step_k"] = tm.worst_k;
    j["median_step_instructions"] = kInstructionsPerTick * ticks[ticks.size() / 2];
  }
  j["wall_time_s"] = wall;

  if (twin) {
    double ss = 0, worst = 0, t_res = -1, t_drift = -1;
    long long res_alarms = 0, drift_alarms = 0, used = 0;
    std::uint64_t stories = 0;
    for (long long k = 0; k < K; ++k) {
      if (!got[k]) continue;
      const Telemetry& t = tel[k];
      if (!(t.flags & link::kAuxMissing)) ss += t.aux * t.aux, ++used, worst = std::max(worst, std::fabs(t.aux));
      if (t.flags & link::kResidualAlarm) {
        ++res_alarms;
        if (t_res < 0) t_res = static_cast<double>(k) * h;
      }
      if (t.flags & link::kDriftAlarm) {
        ++drift_alarms;
        stories |= t.drift_alarms;
        if (t_drift < 0) t_drift = static_cast<double>(k) * h;
      }
    }
    json alarmed = json::array();
    for (int i = 0; i < n; ++i)
      if (stories >> i & 1) alarmed.push_back(i + 1);
    j["twin"] = {{"truth_stiffness_scale", o.truth_stiffness_scale},
                 {"residual_rms_mps2", used ? std::sqrt(ss / static_cast<double>(used)) : 0.0},
                 {"residual_max_mps2", worst},
                 {"residual_limit_mps2", o.residual_limit_mps2},
                 {"residual_alarm_steps", res_alarms},
                 {"first_residual_alarm_s", t_res < 0 ? json(nullptr) : json(t_res)},
                 {"drift_limit_m", o.drift_limit_m},
                 {"drift_alarm_steps", drift_alarms},
                 {"first_drift_alarm_s", t_drift < 0 ? json(nullptr) : json(t_drift)},
                 {"stories_alarmed", alarmed}};
  }
  if (hybrid) {
    // Tracking: desired table motion (the frame's top floor) against the
    // table's measured motion.
    double ss = 0, peak = 0, dss = 0, dpeak = 0, peak_h = 0, peak_p = 0;
    long long used = 0;
    for (long long k = 0; k < K; ++k) {
      if (!got[k]) continue;
      const double err = tel[k].x[n - 1] - table_x[k];
      ss += err * err, peak = std::max(peak, std::fabs(err)), ++used;
      const double d = tel[k].x[n - 1] - offline[k].x[n - 1];
      dss += d * d, dpeak = std::max(dpeak, std::fabs(d));
      peak_h = std::max(peak_h, std::fabs(tel[k].x[n - 1]));
      peak_p = std::max(peak_p, std::fabs(offline[k].x[n - 1]));
    }
    j["hybrid"] = {{"actuator", {{"hz", o.actuator_hz}, {"zeta", o.actuator_zeta}, {"delay_s", o.actuator_delay_s}}},
                   {"compensation_delay_s", o.comp_delay_s},
                   {"compensation_order", o.comp_order},
                   {"force_noise_n", o.force_noise_n},
                   {"force_lsb_n", o.force_lsb_n},
                   {"tracking_rms_m", used ? std::sqrt(ss / static_cast<double>(used)) : 0.0},
                   {"tracking_peak_m", peak},
                   {"top_diff_from_pure_rms_m", used ? std::sqrt(dss / static_cast<double>(used)) : 0.0},
                   {"top_diff_from_pure_peak_m", dpeak},
                   {"peak_top_hybrid_m", peak_h},
                   {"peak_top_pure_m", peak_p}};
  }

  if (!o.csv.empty()) {
    std::ofstream f(o.csv);
    if (!f) throw std::runtime_error("--csv " + o.csv + ": cannot write");
    f << "k,t_s,ag_sent_mps2,ag_used_mps2,received,flags,latency_us,x_top_m,x_top_offline_m,deviation_m,acc_top_mps2,"
         "Ee_Js,particle_x_m,contact_force_n,dissipated_J,aux,drift_alarms";
    if (hybrid) f << ",table_x_m,force_measured_n";
    f << '\n';
    char buf[512];
    for (long long k = 0; k < K; ++k) {
      const Telemetry& t = tel[k];
      std::snprintf(buf, sizeof buf, "%lld,%.6f,%.17g,%.17g,%d,%u,%.1f,%.17g,%.17g,%.3g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%llu",
                    k, static_cast<double>(k) * h, sensed[k], t.ag, got[k] ? 1 : 0, t.flags,
                    got[k] ? 1e6 * (arrival[k] - handled[k]) : 0.0, t.x[n - 1], offline[k].x[n - 1],
                    got[k] ? std::fabs(t.x[n - 1] - offline[k].x[n - 1]) : 0.0, t.acc_top, t.elastic_energy,
                    t.particle_x, t.contact_force, t.dissipated, t.aux,
                    static_cast<unsigned long long>(t.drift_alarms));
      f << buf;
      if (hybrid) {
        std::snprintf(buf, sizeof buf, ",%.17g,%.17g", table_x[k], force[k]);
        f << buf;
      }
      f << '\n';
    }
  }
  return j;
}

}  // namespace vines::host
