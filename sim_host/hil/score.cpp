#include "sim_host/hil/score.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace vines::host {
namespace {

using link::Telemetry;

std::optional<HilStats> stats(std::vector<double> v) {
  if (v.empty()) return std::nullopt;
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  auto q = [&](double p) { return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))]; };
  return HilStats{sum / static_cast<double>(v.size()), q(0.5), q(0.99), v.back()};
}

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

// Telemetry within the divergence limit and finite.
bool finite(const Bench& b, const Telemetry& t) {
  for (int i = 0; i < t.n; ++i)
    if (!(std::fabs(t.x[i]) < b.scene.params.loop.divergence_limit_m)) return false;
  return std::isfinite(t.acc_top) && std::isfinite(t.aux);
}

// Whether the node of the event's life reported `code` for a k in [lo, hi].
bool fault_seen(const HilRecord& rec, const FaultEvent& e, link::FaultCode code, long long lo, long long hi) {
  for (std::size_t i = 0; i < rec.faults.size(); ++i)
    if (rec.fault_life[i] == e.life && rec.faults[i].code == code && rec.faults[i].k >= lo && rec.faults[i].k <= hi)
      return true;
  return false;
}

// Whether the node reported a sequence gap covering one of the event's frames.
bool seq_missing(const HilRecord& rec, const FaultEvent& e) {
  for (unsigned s : e.seqs)
    for (std::size_t i = 0; i < rec.faults.size(); ++i)
      if (rec.fault_life[i] == e.life && rec.faults[i].code == link::FaultCode::kSeqGap &&
          static_cast<std::uint16_t>(s - rec.faults[i].k) < rec.faults[i].count)
        return true;
  return false;
}

// The faults of one kind, each (first sample, samples it covers).
using Hits = std::vector<std::pair<long long, long long>>;

// A kind's verdict (docs/link_protocol.md, "Survived"): every telemetry from
// its first fault on finite; on each sample from there outside the recovery
// windows (a fault's samples, then --node-stall periods), telemetry came and
// the top floor is within `bound` of `reference` (the clean run of the
// node's life). Faults running to the end leave the last sample judged.
void judge(const Bench& b, const HilRecord& rec, const std::vector<Telemetry>& reference, const Hits& hits,
           double bound, HilFaultCounts* c) {
  const long long K = rec.samples, recovery = static_cast<long long>(std::ceil(b.opt.node_stall_periods));
  const int top = b.scene.params.frame.stories - 1;
  long long first = K;
  for (const auto& [k, span] : hits) first = std::min(first, k);
  std::vector<char> judged(static_cast<std::size_t>(K), 0);
  for (long long j = first; j < K; ++j) judged[j] = 1;
  for (const auto& [k, span] : hits)
    for (long long j = k; j < std::min(K, k + span + recovery); ++j) judged[j] = 0;
  if (std::find(judged.begin(), judged.end(), 1) == judged.end()) judged[K - 1] = 1;
  bool finite_all = true;
  for (long long j = std::min(first, K - 1); j < K; ++j) {
    if (rec.got[j] && !finite(b, rec.tel[j])) finite_all = false;
    if (!judged[j]) continue;
    if (!rec.got[j]) ++c->unanswered;
    else c->deviation_m = std::max(c->deviation_m, std::fabs(rec.tel[j].x[top] - reference[j].x[top]));
  }
  if (!finite_all) c->deviation_m = std::numeric_limits<double>::infinity();
  c->bound_m = bound;
  c->ok = finite_all && c->unanswered == 0 && c->deviation_m <= bound;
  c->survived = c->ok ? c->injected : 0;
}

// Each event detected (the node's fault for it); the clipped samples as the
// kind "saturate"; each kind judged survived or not against the clean run's
// peak top-floor displacement.
void score_faults(const Bench& b, const HilRecord& rec, const std::vector<Telemetry>& offline,
                  const std::vector<Telemetry>& reference, std::vector<FaultEvent>* events, HilReport* r) {
  const long long K = rec.samples;
  const int top = b.scene.params.frame.stories - 1;
  double bound = 0;
  for (const Telemetry& t : offline) bound = std::max(bound, std::fabs(t.x[top]));
  r->survival_bound_m = bound;
  std::map<std::string, Hits> hits;
  for (FaultEvent& e : *events) {
    const unsigned s0 = e.seqs.empty() ? 0 : e.seqs[0];
    switch (e.kind) {
      case FaultKind::kDrop:
      case FaultKind::kCorrupt: e.detected = seq_missing(rec, e); break;
      case FaultKind::kDuplicate: e.detected = fault_seen(rec, e, link::FaultCode::kDuplicate, s0, s0); break;
      case FaultKind::kReorder: e.detected = fault_seen(rec, e, link::FaultCode::kReordered, s0, s0); break;
      case FaultKind::kLate: e.detected = fault_seen(rec, e, link::FaultCode::kLate, e.k, e.k); break;
      case FaultKind::kNonFinite: e.detected = fault_seen(rec, e, link::FaultCode::kNonFinite, e.k, e.k); break;
      case FaultKind::kStall: e.detected = fault_seen(rec, e, link::FaultCode::kStall, e.k, e.k + e.span); break;
      default: break;
    }
    HilFaultCounts& c = r->faults[fault_kind_name(e.kind)];
    c.injected += 1, c.detected += e.detected;
    hits[fault_kind_name(e.kind)].emplace_back(e.k, e.span);
  }
  // Saturation counts on samples that reach the node on time and intact and
  // that it stepped (a clipped sample that is also dropped, late, ... is that
  // other fault; one in flight when its node was killed never arrived). The
  // node sends a step's faults before its telemetry, on one ordered stream.
  std::vector<char> clipped = rec.clipped;
  for (const FaultEvent& e : *events)
    for (long long j = e.k; j < e.k + (e.kind == FaultKind::kStall ? e.span : 1); ++j) clipped[j] = 0;
  long long clipped_n = 0, clipped_seen = 0;
  for (long long k = 0; k < K; ++k) clipped_n += clipped[k] && rec.got[k];
  for (const link::Fault& f : rec.faults)
    clipped_seen += f.code == link::FaultCode::kSaturated && f.k < K && clipped[f.k] && rec.got[f.k];
  if (clipped_n > 0) {
    r->faults["saturate"] = {clipped_n, clipped_seen};
    for (long long k = 0; k < K; ++k)
      if (clipped[k] && rec.got[k]) hits["saturate"].emplace_back(k, 1);
  }
  for (auto& [name, c] : r->faults) {
    judge(b, rec, reference, hits[name], bound, &c);
    r->survived = r->survived && c.ok;
    r->faults_injected += c.injected, r->faults_detected += c.detected, r->faults_survived += c.survived;
  }
  for (FaultEvent& e : *events) e.survived = r->faults[fault_kind_name(e.kind)].ok;
  for (int c = 0; c < link::kFaultCodes; ++c) {
    long long count = 0;
    for (const link::Fault& f : rec.faults) count += static_cast<int>(f.code) == c;
    if (count) r->node_faults[link::fault_name(static_cast<link::FaultCode>(c))] = count;
  }
}

// Steps, deadline misses, latency and the deviation from the offline run.
void score_steps(const Bench& b, const HilRecord& rec, const std::vector<Telemetry>& offline, HilReport* r) {
  bool exact = true;
  std::vector<double> latency_us;
  const double h = b.h, deadline = b.opt.deadline_periods * h;
  const int n = b.scene.params.frame.stories;
  for (long long k = 0; k < rec.samples; ++k) {
    if (!rec.got[k]) {
      ++r->missing_steps, ++r->deadline_misses;
      continue;
    }
    ++r->steps;
    const Telemetry& t = rec.tel[k];
    // Real time: telemetry due by the sample's time plus the deadline; virtual
    // clock: its latency (sample sent to telemetry back; a step without its
    // sample: from when the bench handled it) within the deadline.
    const std::optional<double> latency = rec.latency(k);
    const double late = b.opt.realtime ? rec.arrival[k] - static_cast<double>(k) * h
                                       : latency.value_or(rec.arrival[k] - rec.handled[k]);
    if (latency) latency_us.push_back(1e6 * *latency);
    // A board in QEMU keeps the board's time, not the host's: its deadline is
    // the step's cost on its counter against the budget (one period).
    if (b.board ? t.step_ticks > rec.final_status.timing.budget_ticks : late > deadline) ++r->deadline_misses;
    r->outputs_finite = r->outputs_finite && finite(b, t);
    for (int i = 0; i < n; ++i) {
      r->max_deviation_from_offline = std::max(r->max_deviation_from_offline, std::fabs(t.x[i] - offline[k].x[i]));
      r->max_abs_floor_displacement_m = std::max(r->max_abs_floor_displacement_m, std::fabs(t.x[i]));
    }
    exact = exact && equal_outputs(t, offline[k]);
  }
  if (!r->outputs_finite) r->max_deviation_from_offline = std::numeric_limits<double>::infinity();
  const link::StepTiming& tm = rec.final_status.timing;
  r->deadline_s = b.board && tm.counter_hz ? static_cast<double>(tm.budget_ticks) / tm.counter_hz : deadline;
  r->latency_us = stats(latency_us);
  // Hybrid: the node's plant is the lab, never the offline run.
  r->bit_exact = exact && r->missing_steps == 0 && b.opt.mode != HilMode::kHybrid;
}

// The node's status, its deadline monitor (its counter: ns on the host, the
// 25 MHz timer on a board) and each step's cost from telemetry.
void score_node(const Bench& b, const HilRecord& rec, HilReport* r) {
  const link::StepTiming& tm = rec.final_status.timing;
  r->node_status = {rec.final_status.steps, static_cast<int>(rec.final_status.state), rec.node_exit};
  r->node_deadline = tm;
  std::vector<double> ticks;
  for (long long k = 0; k < rec.samples; ++k)
    if (rec.got[k])
      ticks.push_back(rec.tel[k].step_ticks), r->steps_over_budget += rec.tel[k].step_ticks > tm.budget_ticks;
  r->step_ticks = stats(ticks);
  if (b.board && !ticks.empty()) {
    std::sort(ticks.begin(), ticks.end());
    const double per_tick = instructions_per_tick(tm.counter_hz);
    r->board = HilBoardSteps{kIcountShift, per_tick * tm.worst_ticks, tm.worst_k, per_tick * ticks[ticks.size() / 2]};
  }
}

}  // namespace

HilReport score(const Bench& b, const HilRecord& rec, const std::vector<Telemetry>& offline,
                const std::vector<Telemetry>& reference, std::vector<FaultEvent>* events) {
  HilReport r;
  r.scene = b.scene.name;
  r.mode = b.opt.mode;
  r.realtime = b.opt.realtime;
  r.scalar = b.scene.scalar;
  r.sensor_rate_hz = b.scene.params.loop.sensor_rate_hz;
  r.samples = rec.samples;
  r.node = b.opt.node;
  r.node_restarts = rec.restarts;
  r.bad_frames_from_node = rec.bad_frames;
  r.wall_time_s = rec.wall_s;
  r.bench_service = rec.bench_service;
  r.node_service = rec.node_service;
  score_faults(b, rec, offline, reference, events, &r);
  score_steps(b, rec, offline, &r);
  score_node(b, rec, &r);
  return r;
}

}  // namespace vines::host
