#include "sim_host/hil/link/stream.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <random>

#include "sim_host/hil/link/node_link.hpp"
#include "sim_host/hil/link/realtime.hpp"

namespace vines::host {
namespace {

using link::Telemetry;

class Stream {
 public:
  Stream(const Bench& b, BenchMode& mode, std::vector<FaultEvent>* events, HilWatch* watch)
      : b_(b), o_(b.opt), mode_(mode), watch_(watch), K_(b.samples), rec_(b.samples, b.opt.mode == HilMode::kHybrid),
        at_(static_cast<std::size_t>(b.samples), nullptr), rng_(b.opt.seed + 5) {
    for (FaultEvent& e : *events) at_[static_cast<std::size_t>(e.k)] = &e;
    // The samples as the sensor gives them (clipped at its range).
    rec_.sensed = b.ex.samples;
    const double range = b.cfg.sensor_range_mps2;
    if (range > 0)
      for (long long k = 0; k < K_; ++k)
        if (std::fabs(rec_.sensed[k]) >= range)
          rec_.sensed[k] = std::copysign(range, rec_.sensed[k]), rec_.clipped[k] = 1;
  }

  HilRecord run() {
    // Real-time service for the bench while it runs, and what the host node
    // (asked on its command line) got.
    const RealtimeRequest bench_rt{o_.rt_priority, o_.bench_cpu()}, node_rt{o_.rt_priority, o_.node_cpu()};
    const RealtimeScope rt(bench_rt);
    if (bench_rt.any() || node_rt.any()) rec_.bench_service = rt.grant();
    t0_ = HilClock::now();
    node_ = new_node();
    configure(*node_, b_.cfg, b_.image);
    if ((bench_rt.any() || node_rt.any()) && node_->process() > 0) rec_.node_service = realtime_of(node_->process(), node_rt);
    t0_ = HilClock::now();  // the bench clock starts with the run
    node_->set_epoch(t0_);
    start(*node_, 0, 0);
    for (long long k = 0; k < K_; ++k) step(k);
    for (auto& r : releases_) send_sample(sample_frame(r.second, static_cast<double>(K_) * b_.h), r.second);
    node_->send(node_->encode_empty(link::MsgType::kStop));
    node_->wait_answered();
    rec_.final_status = node_->status();
    rec_.bad_frames += node_->bad_frames();
    rec_.node_exit = node_->finish();
    rec_.wall_s = seconds_since(t0_);
    return std::move(rec_);
  }

 private:
  // A node process (life rec_.restarts) whose telemetry lands in the record.
  std::unique_ptr<NodeLink> new_node() {
    const long long life = rec_.restarts;
    auto n = std::make_unique<NodeLink>(o_, life, &rec_.faults, &rec_.fault_life);
    n->set_epoch(t0_);
    n->on_telemetry = [this, life](const Telemetry& t, double now) {
      if (t.k >= static_cast<std::uint32_t>(K_)) return;
      rec_.tel[t.k] = t;
      rec_.got[t.k] = 1;
      rec_.arrival[t.k] = now;
      rec_.tel_life[t.k] = life;
      mode_.on_telemetry(t);
      if (watch_) watch_->step(t.k, rec_);
    };
    return n;
  }

  // Sample k's frame as sent at now_s (a non-finite fault replaces its value).
  std::vector<std::uint8_t> sample_frame(long long k, double now_s) {
    link::Sample s;
    s.k = static_cast<std::uint32_t>(k);
    s.t_ns = static_cast<std::uint64_t>(std::llround(now_s * 1e9));
    s.ag = rec_.sensed[k];
    s.aux = mode_.aux(k, rec_);
    s.table_x = mode_.table_x(k, rec_);
    s.ny = static_cast<std::uint8_t>(mode_.floors(k, s.y));
    const FaultEvent* e = at_[static_cast<std::size_t>(k)];
    if (e && e->kind == FaultKind::kNonFinite) s.ag = k % 2 ? std::numeric_limits<double>::infinity() : std::nan("");
    return node_->encode(link::MsgType::kSample, s);
  }

  // Sends sample k's frame; its first sending to this node is the time its
  // latency counts from.
  void send_sample(const std::vector<std::uint8_t>& frame, long long k) {
    node_->send(frame);
    const auto i = static_cast<std::size_t>(k);
    if (rec_.sent_life[i] != rec_.restarts) rec_.sent[i] = seconds_since(t0_), rec_.sent_life[i] = rec_.restarts;
  }

  // Kills the node (keeping what it sent before) and starts a new one at
  // sample k.
  void restart(long long k, double due, FaultEvent* e) {
    node_->kill();
    rec_.bad_frames += node_->bad_frames();
    ++rec_.restarts;
    node_ = new_node();
    configure(*node_, b_.cfg, b_.image);
    // The restarted node's clock starts where the bench's is: the wall
    // clock in real time, the sample's due time on the virtual clock (the
    // wall time there would make it hold every step up to it).
    start(*node_, k, static_cast<std::uint64_t>(std::llround((o_.realtime ? seconds_since(t0_) : due) * 1e9)));
    e->life = rec_.restarts;
    e->detected = node_->first_cold_start();
  }

  // One sample: paced, its fault applied, the lab driven, frames sent.
  void step(long long k) {
    const double due = static_cast<double>(k) * b_.h;
    if (o_.realtime) {
      // Read until the sample is due, then send it.
      for (double left = due - seconds_since(t0_); left > 0; left = due - seconds_since(t0_))
        node_->pump(std::min(left, 0.002));
    }
    // Real time: what the node sent meanwhile is read (a bench behind its
    // schedule reads here only).
    if (o_.realtime) node_->pump(0);
    rec_.handled[k] = seconds_since(t0_);
    FaultEvent* e = at_[static_cast<std::size_t>(k)];
    if (e) e->life = rec_.restarts;
    if (e && e->kind == FaultKind::kRestart) restart(k, due, e);
    // The sample's stamp: after a restart in real time, the time it is sent.
    const double now = o_.realtime ? seconds_since(t0_) : due;
    mode_.drive(k, &rec_);
    for (auto r = releases_.lower_bound(k); r != releases_.end() && r->first == k; r = releases_.erase(r))
      send_sample(sample_frame(r->second, now), r->second);
    if (!reordered_.empty() && k == reordered_k_ + 1) {
      send_sample(sample_frame(k, now), k);
      send_sample(reordered_, reordered_k_);
      reordered_.clear();
    } else if (e && e->kind == FaultKind::kStall) {
      for (long long j = k; j < k + e->span; ++j) releases_.emplace(k + e->span, j);
    } else if (e && e->kind == FaultKind::kLate) {
      releases_.emplace(k + e->span, k);
    } else if (!std::any_of(releases_.begin(), releases_.end(), [&](auto& r) { return r.second == k; })) {
      send_on_time(k, now, e);
    }
    // Virtual clock: the node's clock is the samples' stamps, so a few frames
    // may be under way at once without changing what it computes. A board in
    // QEMU takes a byte per turn of QEMU's loop: a window of frames keeps its
    // UART busy; the host node runs in strict lock step (its latency is
    // measured per sample), and so does hybrid mode: the lab moves the table
    // by the command of the step before, which must be there.
    if (!o_.realtime) node_->wait_answered(b_.board && o_.mode != HilMode::kHybrid ? 16 : 0);
  }

  // Sample k sent now, dropped, corrupted, duplicated or held for a reorder.
  void send_on_time(long long k, double now, FaultEvent* e) {
    const unsigned seq = node_->next_seq();
    std::vector<std::uint8_t> f = sample_frame(k, now);
    const FaultKind kind = e ? e->kind : FaultKind::kCount;
    if (e && (kind == FaultKind::kDrop || kind == FaultKind::kCorrupt || kind == FaultKind::kDuplicate ||
              kind == FaultKind::kReorder))
      e->seqs.push_back(seq);
    if (kind == FaultKind::kCorrupt) {
      f[rng_() % (f.size() - 1)] ^= static_cast<std::uint8_t>(1 + rng_() % 255);
    }
    if (kind == FaultKind::kReorder) {
      reordered_ = f;
      reordered_k_ = k;
    } else if (kind != FaultKind::kDrop) {
      send_sample(f, k);
      if (kind == FaultKind::kDuplicate) send_sample(f, k);
    }
  }

  const Bench& b_;
  const HilOptions& o_;
  BenchMode& mode_;
  HilWatch* watch_;  // none: nobody watches
  const long long K_;
  HilRecord rec_;
  std::vector<FaultEvent*> at_;  // the fault planned at each sample
  HilClock::time_point t0_;
  std::unique_ptr<NodeLink> node_;
  std::multimap<long long, long long> releases_;  // release at sample -> sample
  std::vector<std::uint8_t> reordered_;           // frame held back by a reorder
  long long reordered_k_ = -1;
  std::mt19937_64 rng_;                            // which byte a corruption flips, and how
};

}  // namespace

HilRecord stream(const Bench& b, BenchMode& mode, std::vector<FaultEvent>* events, HilWatch* watch) {
  return Stream(b, mode, events, watch).run();
}

}  // namespace vines::host
