// The Engine of the fixed-point firmware (scene loop.scalar = "fixed"): the
// Q3.28 step of fixed/frame.hpp (no device) or fixed/vines_step.hpp (a VI
// NES, the split contact scheme) on a model built, in double, from the
// double one and the scene's loop.fixed_* scales. Outputs are read back in
// double here, on the host: the step itself has no floating point. Every
// saturation of a run is counted (RunTotals::fixed_saturations).
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "sim_host/engines/engine.hpp"
#include "sim_host/engines/model_info.hpp"
#include "vines/build_model.hpp"
#include "vines/contact_laws.hpp"
#include "vines/fixed/frame.hpp"
#include "vines/fixed/vines_step.hpp"
#include "vines/sim.hpp"

namespace vines::host {

// Q3.28, the format of every fixed-point value (docs/fixed_point.md).
inline constexpr int kFixedBits = 28;

// The fixed-point model and step of a device: the bare frame's here, the VI
// NES's below.
template <int N, typename Dev>
struct FixedOf {
  using M = fixed::FixedFrame<kFixedBits, Model<double, N, Dev>::kP>;
  using D = fixed::FixedFrameData<M>;
  static M build(const Model<double, N, Dev>& m, const FixedParams& f) {
    return fixed::build_fixed_frame<kFixedBits>(m, f.accel_mps2, f.amplification);
  }
  static const fixed::FixedFrame<kFixedBits, M::kP>& frame(const M& m) { return m; }
  static const fixed::FixedFrameData<M>& frame(const D& d) { return d; }
  static void init(const M& m, D& d, typename M::Q /*v0*/, typename M::Q a0) { fixed::fixed_frame_init(m, d, a0); }
  static void step(const M& m, D& d, typename M::Q a1) { fixed::fixed_frame_step(m, d, a1); }
};

template <int N, ContactLaw L>
struct FixedOf<N, VinesDevice<L>> {
  using M = decltype(fixed::build_fixed_vines<kFixedBits, fixed::kFixedMoments, LawOf<L>>(
      std::declval<const Model<double, N, VinesDevice<L>>&>(), fixed::FixedScales{}));
  using D = fixed::FixedVinesData<M>;
  static M build(const Model<double, N, VinesDevice<L>>& m, const FixedParams& f) {
    return fixed::build_fixed_vines<kFixedBits, fixed::kFixedMoments, LawOf<L>>(
        m, fixed::FixedScales{f.accel_mps2, f.amplification, f.contact_speed_mps});
  }
  static const typename M::Frame& frame(const M& m) { return m.frame; }
  static const fixed::FixedFrameData<typename M::Frame>& frame(const D& d) { return d.frame; }
  static void init(const M& m, D& d, typename M::Q v0, typename M::Q a0) { fixed::fixed_vines_init(m, d, v0, a0); }
  static void step(const M& m, D& d, typename M::Q a1) { fixed::fixed_vines_step(m, d, a1); }
};

template <int N, typename Dev>
class FixedEngine final : public Engine {
  static constexpr bool kVines = Dev::kKind == DeviceKind::kVines;
  using Of = FixedOf<N, Dev>;
  using FM = typename Of::M;
  using FD = typename Of::D;
  using Q = typename FM::Q;
  using DModel = Model<double, N, Dev>;
  using DData = Data<double, N, Dev>;
  static constexpr int P = DModel::kP;

 public:
  ParamError build(const SceneParams& p) override {
    if (kVines && p.loop.contact_scheme != ContactScheme::kSplit)
      return {"loop.contact_scheme", "loop.scalar = \"fixed\" runs the split contact scheme only: set it to \"split\""};
    if (p.loop.energy_ledger)
      return {"loop.energy_ledger", "not kept in fixed point yet (loop.scalar = \"fixed\"): set it to false"};
    const ParamError e = build_model(p, dm_.get());
    if (!e.ok()) return e;
    fixed_ = p.fixed;
    *fm_ = Of::build(*dm_, fixed_);
    return {};
  }
  ParamError set_initial_conditions(const SceneParams& p) override {
    const ParamError e = vines::set_initial_conditions(p.device, dm_.get());
    if (e.ok()) *fm_ = Of::build(*dm_, fixed_);
    return e;
  }
  std::vector<std::uint8_t> model_image() const override { return {}; }
  std::string load_image(const std::uint8_t*, std::size_t) override {
    return "a fixed-point engine (loop.scalar = \"fixed\") has no model image yet";
  }
  ModelInfo info() const override { return model_info(*dm_); }

  void init(double a0) override {
    const std::uint32_t sat0 = numeric::fixed_saturations();
    count_ = Counters{};
    last_good_ = 0;  // a non-finite first sample is held at 0 (and counted)
    Q v0 = Q(0);
    if constexpr (kVines) v0 = Q(dm_->dev.v0 / fm_->speed);
    Of::init(*fm_, *fd_, v0, sample(a0));
    saturations_ = numeric::fixed_saturations() - sat0;
    peaks_.setZero();
    drifts_.setZero();
    strain_increments_ = 0;
    last_strain_ = 0;
  }
  void step(double a1) override { run(&a1, 1); }
  void run(const double* a, std::size_t n) override {
    const std::uint32_t sat0 = numeric::fixed_saturations();
    for (std::size_t k = 0; k < n; ++k) {
      Of::step(*fm_, *fd_, sample(a[k]));
      if (dm_->loop.floor_peaks) floor_peaks();
    }
    saturations_ += numeric::fixed_saturations() - sat0;
  }

  Snapshot snapshot() const override {
    const auto& fd = Of::frame(*fd_);
    const DData& d = shadow();
    Snapshot s;
    s.t = fd.steps * dm_->h;
    s.ag = static_cast<double>(fd.a_prev) * fm_frame().sa;
    const auto x = floor_displacements(*dm_, d), v = floor_velocities(*dm_, d), acc = absolute_accel(*dm_, d);
    for (int i = 0; i < N; ++i) {
      s.x[i] = x(i);
      s.v[i] = v(i);
      s.acc[i] = acc(i);
      s.drift[i] = s.x[i] - (i ? s.x[i - 1] : 0.0);
    }
    s.elastic_energy = static_cast<double>(fd.ee) * fm_frame().ee_unit;
    if constexpr (kVines) {
      s.particle_x = dm_->dev.y0 + d.s;
      s.particle_v = d.sd;
      s.wall_left = s.x[dm_->floor] - dm_->dev.design.gap;
      s.wall_right = s.x[dm_->floor] + dm_->dev.design.gap;
      s.contact_force = d.contact_force;
      s.mode = static_cast<int>(d.mode);
    }
    return s;
  }

  Probe probe() const override {
    Probe p;
    p.count = counters();
    p.peak_top = static_cast<double>(Of::frame(*fd_).peak_top) * fm_frame().top_length;
    if constexpr (kVines) {
      const DData& d = shadow();
      p.mode = static_cast<int>(d.mode);
      const double r = d.s - d.xf;
      p.overlap = std::fmax(dm_->dev.wall_left - r, r - dm_->dev.wall_right);
    }
    return p;
  }

  RunTotals totals() const override {
    const auto& fd = Of::frame(*fd_);
    RunTotals r;
    for (int i = 0; i < N; ++i) {
      r.peak_x[i] = peaks_(i);
      r.peak_drift[i] = drifts_(i);
    }
    r.peak_top = static_cast<double>(fd.peak_top) * fm_frame().top_length;
    r.peak_x[N - 1] = std::fmax(r.peak_x[N - 1], r.peak_top);
    r.t_peak_top = fd.peak_step * dm_->h;
    r.peak_top_velocity = static_cast<double>(fd.peak_top_velocity) * fm_frame().top_speed;
    r.elastic_energy = static_cast<double>(fd.ee) * fm_frame().ee_unit;
    r.strain_increments = strain_increments_;
    if constexpr (kVines) r.max_overlap = static_cast<double>(fd_->max_depth) * fm_->cu.u.d;
    r.count = counters();
    r.fixed_saturations = saturations_;
    return r;
  }

 private:
  const fixed::FixedFrame<kFixedBits, P>& fm_frame() const { return Of::frame(*fm_); }

  // A sample in the model's unit; a non-finite one is replaced by the last
  // good one and counted, as the double loop does.
  Q sample(double a) {
    if (std::isfinite(a)) last_good_ = a;
    else ++count_.bad_samples;
    return Q(last_good_ / fm_frame().sa);
  }

  // The fixed state read back in double, in a Data of the double model (for
  // the double model's output functions): modes, particle, contact force.
  const DData& shadow() const {
    DData& d = *shadow_;
    shadow_modes();
    if constexpr (kVines) {
      const FM& m = *fm_;
      d.s = static_cast<double>(fd_->s) * m.length;
      d.sd = static_cast<double>(fd_->sd) * m.speed;
      d.xf = dm_->floor_x(d.z)(dm_->floor);
      const double vf = dm_->floor_v(d.z)(dm_->floor);
      const int side = fd_->side;
      d.mode = side < 0 ? Mode::kContactLeft : side > 0 ? Mode::kContactRight : Mode::kFree;
      d.contact_force = 0;
      if (side != 0) {
        const double overlap = static_cast<double>(fd_->overlap) * m.length, rate = side * (d.sd - vf);
        d.contact_force = -side * dm_->dev.law(overlap, rate).total();
      }
    }
    return d;
  }

  // The modes alone, in SI, into the shadow Data.
  void shadow_modes() const {
    const auto& fd = Of::frame(*fd_);
    const auto& fr = fm_frame();
    for (int j = 0; j < P; ++j) {
      shadow_->z(j) = static_cast<double>(fd.z(j)) * fr.sq(j);
      shadow_->z(P + j) = static_cast<double>(fd.z(P + j)) * fr.sv(j);
    }
  }

  Counters counters() const {
    Counters c = count_;
    c.steps = Of::frame(*fd_).steps;
    if constexpr (kVines) {
      const FD& d = *fd_;
      c.careful_steps = d.careful;
      c.substeps = c.contact_substeps = d.contact_steps;
      c.events = d.events;
      c.contacts = d.contacts;
      c.cap_hits = d.capped;
      c.max_substeps_in_step = d.max_contact_steps;
    }
    return c;
  }

  // The floors' peaks, drifts and positive strain increments (loop.floor_peaks), in double.
  void floor_peaks() {
    shadow_modes();  // the floors need the modes only, not the particle's contact force
    const DData& d = *shadow_;
    const Eigen::Matrix<double, N, 1> x = dm_->floor_x(d.z);
    peaks_ = peaks_.cwiseMax(x.cwiseAbs());
    for (int i = 0; i < N; ++i) drifts_(i) = std::fmax(drifts_(i), std::fabs(x(i) - (i ? x(i - 1) : 0.0)));
    const double strain = dm_->strain.eval(d.z, 0.0);
    if (strain > last_strain_) strain_increments_ += strain - last_strain_;
    last_strain_ = strain;
  }

  // Heap on the host (the blocks can be large); the firmware keeps them static.
  std::unique_ptr<DModel> dm_ = std::make_unique<DModel>();
  std::unique_ptr<FM> fm_ = std::make_unique<FM>();
  std::unique_ptr<FD> fd_ = std::make_unique<FD>();
  std::unique_ptr<DData> shadow_ = std::make_unique<DData>();
  FixedParams fixed_;
  Counters count_;
  double last_good_ = 0;
  std::int64_t saturations_ = 0;
  Eigen::Matrix<double, N, 1> peaks_ = Eigen::Matrix<double, N, 1>::Zero(), drifts_ = peaks_;
  double strain_increments_ = 0, last_strain_ = 0;
};

}  // namespace vines::host
