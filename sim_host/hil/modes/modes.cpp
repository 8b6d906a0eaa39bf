#include "sim_host/hil/modes/modes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "sim_host/engines/build_engine.hpp"
#include "sim_host/hil/modes/lab.hpp"
#include "sim_host/hil/modes/rths_criteria.hpp"
#include "sim_host/hil/offline.hpp"

namespace vines::host {
namespace {

using link::Telemetry;

// Replay: the node's plant is the scene; nothing to add.
class ReplayMode : public BenchMode {};

// Hybrid: the node's bare frame commands the table (its top floor's motion);
// the lab moves the table with the scene's device on it (VI NES or TMD), and
// the load cell's force goes back to the node.
class HybridMode : public BenchMode {
 public:
  HybridMode(const Bench& b, const Telemetry& initial) : b_(b) {
    const Scene& sc = b.scene;
    const std::unique_ptr<Engine> eng = build_engine(sc.params, sc.scalar, sc.path);
    const HilOptions& o = b.opt;
    const LabOptions lo{o.actuator_hz, o.actuator_zeta, o.actuator_delay_s, o.force_noise_n, o.force_lsb_n, o.seed};
    // The specimen where the pure simulation starts it: the VI NES particle
    // as the offline run reads it, the TMD at its initial conditions
    // (relative to the top floor, at rest at 0 like the table).
    Specimen sp;
    sp.kind = sc.params.device.kind;
    sp.vines = eng->info().vines;
    sp.law = sc.params.device.vines.law;
    sp.tmd = eng->info().tmd;
    const TmdParams& tp = sc.params.device.tmd;
    sp.x0 = sp.kind == DeviceKind::kTmd ? tp.initial_position_m : initial.particle_x;
    sp.v0 = sp.kind == DeviceKind::kTmd ? tp.initial_velocity_mps : initial.particle_v;
    lab_ = std::make_unique<ShakeTable>(sp, b.h, lo);
    // The bare frame on the same samples: the reference of x_r and E_r.
    link::NodeConfig bare = b.cfg;
    bare.mode = link::NodeMode::kReplay;
    bare.scene.device.kind = DeviceKind::kNone;
    const std::vector<Telemetry> t = offline_run(bare, b.ex.samples, sc.path);
    const int top = sc.params.frame.stories - 1;
    for (const Telemetry& s : t) bare_peak_ = std::max(bare_peak_, std::fabs(s.x[top]));
    bare_ee_ = t.back().elastic_energy;
  }

  // The table follows the last command received; the load cell reads the
  // specimen at the sample instant.
  void drive(long long k, HilRecord* rec) override {
    const std::vector<double>& a = b_.ex.samples;
    rec->force[k] = k == 0 ? 0.0 : lab_->advance(last_command_, a[k - 1], a[k]);
    rec->table_x[k] = lab_->table_x();
  }
  double aux(long long k, const HilRecord& rec) const override { return rec.force[k]; }
  double table_x(long long k, const HilRecord& rec) const override { return rec.table_x[k]; }
  void on_telemetry(const Telemetry& t) override { last_command_ = t.aux; }

  // Tracking: desired table motion (the frame's top floor) against the
  // table's measured motion; the top floor against the pure simulation.
  void report(const HilRecord& rec, const std::vector<Telemetry>& offline, HilReport* r) const override {
    const HilOptions& o = b_.opt;
    HilHybridReport hy;
    const int n = b_.scene.params.frame.stories;
    double ss = 0, dss = 0;
    long long used = 0;
    for (long long k = 0; k < rec.samples; ++k) {
      if (!rec.got[k]) continue;
      const Telemetry& t = rec.tel[k];
      const double err = t.x[n - 1] - rec.table_x[k];
      ss += err * err, hy.tracking_peak_m = std::max(hy.tracking_peak_m, std::fabs(err)), ++used;
      const double d = t.x[n - 1] - offline[k].x[n - 1];
      dss += d * d, hy.top_diff_from_pure_peak_m = std::max(hy.top_diff_from_pure_peak_m, std::fabs(d));
      hy.peak_top_hybrid_m = std::max(hy.peak_top_hybrid_m, std::fabs(t.x[n - 1]));
      hy.peak_top_pure_m = std::max(hy.peak_top_pure_m, std::fabs(offline[k].x[n - 1]));
    }
    hy.actuator_hz = o.actuator_hz, hy.actuator_zeta = o.actuator_zeta, hy.actuator_delay_s = o.actuator_delay_s;
    hy.compensation = o.comp;
    hy.compensation_delay_s = o.comp_delay_s;
    hy.compensation_order = o.comp_order;
    hy.compensation_window_s = o.comp_window_s;
    if (o.comp == HilComp::kAdaptive) hy.adaptive = coefficients(rec);
    hy.force_noise_n = o.force_noise_n, hy.force_lsb_n = o.force_lsb_n;
    hy.tracking_rms_m = used ? std::sqrt(ss / static_cast<double>(used)) : 0.0;
    hy.top_diff_from_pure_rms_m = used ? std::sqrt(dss / static_cast<double>(used)) : 0.0;
    criteria(rec, offline, &hy);
    // x_r, E_r: the hybrid frame's last telemetry, the pure simulation's end.
    const Telemetry* last = &offline[0];
    for (long long k = 0; k < rec.samples; ++k)
      if (rec.got[k]) last = &rec.tel[k];
    hy.x_r_hybrid = 1 - hy.peak_top_hybrid_m / bare_peak_;
    hy.x_r_pure = 1 - hy.peak_top_pure_m / bare_peak_;
    hy.E_r_hybrid = 1 - last->elastic_energy / bare_ee_;
    hy.E_r_pure = 1 - offline.back().elastic_energy / bare_ee_;
    r->hybrid = hy;
  }

  // The adaptive compensator's coefficients from the telemetry: the last
  // received, and their range over the run.
  static HilAtsCoefficients coefficients(const HilRecord& rec) {
    HilAtsCoefficients c;
    bool first = true;
    for (long long k = 0; k < rec.samples; ++k) {
      if (!rec.got[k]) continue;
      for (int i = 0; i < 3; ++i) {
        const double v = rec.tel[k].comp[i];
        c.last[i] = v;
        c.min[i] = first ? v : std::min(c.min[i], v);
        c.max[i] = first ? v : std::max(c.max[i], v);
      }
      first = false;
    }
    return c;
  }

  // The vRTHS benchmark's criteria (rths_criteria.hpp) on the whole run: the
  // table against the frame's top floor (the target before compensation),
  // each floor against the pure simulation. A step without telemetry holds
  // the node's last one.
  void criteria(const HilRecord& rec, const std::vector<Telemetry>& offline, HilHybridReport* hy) const {
    const int n = b_.scene.params.frame.stories;
    const auto K = static_cast<std::size_t>(rec.samples);
    std::vector<std::vector<double>> hybrid(static_cast<std::size_t>(n), std::vector<double>(K)),
        pure(static_cast<std::size_t>(n), std::vector<double>(K));
    const Telemetry* last = &offline[0];
    for (std::size_t k = 0; k < K; ++k) {
      if (rec.got[k]) last = &rec.tel[k];
      for (int i = 0; i < n; ++i) hybrid[i][k] = last->x[i], pure[i][k] = offline[k].x[i];
    }
    const std::vector<double>& target = hybrid[static_cast<std::size_t>(n - 1)];
    if (K >= 3) {
      const std::optional<double> d = rths::tracking_delay_s(target, rec.table_x, b_.h, std::max(0.1, 2 * b_.h));
      if (d) hy->tracking_delay_ms = 1e3 * *d;
    }
    hy->tracking_rms_pct = rths::rms_error_pct(target, rec.table_x);
    hy->tracking_peak_pct = rths::peak_error_pct(target, rec.table_x);
    for (int i = 0; i < n; ++i) {
      hy->response_rms_pct.push_back(rths::rms_error_pct(pure[i], hybrid[i]));
      hy->response_peak_pct.push_back(rths::peak_error_pct(pure[i], hybrid[i]));
    }
  }

 private:
  const Bench& b_;
  std::unique_ptr<ShakeTable> lab_;
  double last_command_ = 0;
  double bare_peak_ = 0, bare_ee_ = 0;  // the bare frame's peak top-floor displacement and E_e
};

}  // namespace

std::unique_ptr<BenchMode> make_mode(const Bench& b, const std::vector<Telemetry>& offline) {
  switch (b.opt.mode) {
    case HilMode::kTwin: return make_twin_mode(b);
    case HilMode::kHybrid: return std::make_unique<HybridMode>(b, offline[0]);
    default: return std::make_unique<ReplayMode>();
  }
}

}  // namespace vines::host
