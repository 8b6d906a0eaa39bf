// The Engine of the fixed-point firmware (scene loop.scalar = "fixed"): a
// device's node model (fixed/node_model.hpp: the Q3.28 step of
// fixed/frame.hpp (no device), fixed/tmd.hpp (a TMD: the dense step in real
// block-diagonal form) or fixed/vines_step.hpp (a VI NES, the split contact
// scheme), its readout and initial conditions) built, in double, from the
// double model and the scene's loop.fixed_* scales; the same block a
// fixed-point board loads as its model image. The step itself has no
// floating point. The floors, the top floor's acceleration, E_e and the
// particle are read as the board reads them (fixed/readout.hpp), so its
// telemetry equals this engine's bit for bit; the rest (velocities, the
// TMD, the other floors' accelerations, the strain) is read back in double
// on a shadow of the double model's data. Every saturation of a run is
// counted (RunTotals::fixed_saturations).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "sim_host/engines/engine.hpp"
#include "sim_host/engines/loop_state.hpp"
#include "sim_host/engines/model_info.hpp"
#include "vines/build/build_model.hpp"
#include "vines/fixed/image.hpp"
#include "vines/fixed/node_model.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/step/sim.hpp"

namespace vines::host {

template <int N, typename Dev>
class FixedEngine final : public Engine {
  static constexpr bool kVines = Dev::kKind == DeviceKind::kVines;
  static constexpr bool kTmd = Dev::kKind == DeviceKind::kTmd;
  using NM = fixed::NodeModel<N, Dev>;
  using Of = typename NM::Step;
  using FM = typename NM::M;
  using FD = typename NM::D;
  using Q = typename FM::Q;
  using DModel = Model<double, N, Dev>;
  using DData = Data<double, N, Dev>;
  static constexpr int P = DModel::kP;
  // state() and load_state() copy the node data as bytes: plain members and
  // fixed-size Eigen matrices, no pointer, nothing owned, no virtual table.
  static_assert(!std::is_polymorphic_v<FD> && std::is_trivially_destructible_v<FD> &&
                    std::is_trivially_copyable_v<fixed::SampleHold> && std::is_trivially_copyable_v<Counters>,
                "the fixed engine's state must be copyable as bytes");

 public:
  ParamError build(const SceneParams& p) override {
    fingerprint_.forget();
    if (kVines && p.loop.contact_scheme != ContactScheme::kSplit)
      return {"loop.contact_scheme", "loop.scalar = \"fixed\" runs the split contact scheme only: set it to \"split\""};
    if (kTmd && p.loop.energy_ledger)
      return {"loop.energy_ledger", "not kept for a TMD in fixed point (its state is not modal): set it to false, "
                                    "or run the scene in double or float"};
    const ParamError e = build_model(p, dm_.get());
    if (!e.ok()) return e;
    fixed_ = p.fixed;
    fixed::build_node_model(*dm_, fixed_, nm_.get());
    if constexpr (kTmd) {
      if (!nm_->step.ok)
        return {"loop.scalar", "no fixed-point block form for this TMD (its transition has a defective or "
                               "ill-conditioned eigenbasis): run it in double or float"};
    }
    return {};
  }
  ParamError set_initial_conditions(const SceneParams& p) override {
    fingerprint_.forget();
    const ParamError e = vines::set_initial_conditions(p.device, dm_.get());
    if (e.ok()) fixed::build_node_model(*dm_, fixed_, nm_.get());
    return e;
  }
  // The fixed-point model image (fixed/image.hpp): the node model's bytes.
  std::vector<std::uint8_t> model_image() const override {
    const fixed::ImageKind k = fixed::image_kind<N, Dev>();
    std::vector<std::uint8_t> out(fixed::kImageHeaderBytes + k.body);
    out.resize(fixed::write_image(k, nm_.get(), out.data(), out.size()));
    return out;
  }
  // An image replaces the node model built from the scene (whose double
  // model still reads the state back), as on a board.
  std::string load_image(const std::uint8_t* p, std::size_t n) override {
    auto loaded = std::make_unique<NM>();
    fixed::ImageLoader loader(fixed::image_kind<N, Dev>(), loaded.get());
    const char* why = loader.push(p, n);
    if (!why) why = loader.finish();
    if (why) return why;
    nm_ = std::move(loaded);
    fingerprint_.forget();
    return {};
  }
  ModelInfo info() const override { return model_info(*dm_); }

  void init(double a0) override {
    const std::uint32_t sat0 = numeric::fixed_saturations();
    count_ = Counters{};
    hold_ = fixed::SampleHold{};  // a non-finite first sample is held at 0 (and counted)
    fixed::node_init(*nm_, *fd_, sample(a0));
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
      fixed::node_step(*nm_, *fd_, sample(a[k]));
      if (dm_->loop.floor_peaks) floor_peaks();
    }
    saturations_ += numeric::fixed_saturations() - sat0;
  }

  Snapshot snapshot() const override {
    const auto& fd = Of::frame(*fd_);
    const fixed::NodeReading<N> r = fixed::read_node(*nm_, *fd_);
    const DData& d = shadow(r.contact_force);
    Snapshot s;
    s.t = fd.steps * dm_->h;
    s.ag = static_cast<double>(fd.a_prev) * fm_frame().sa;
    const auto v = floor_velocities(*dm_, d), acc = absolute_accel(*dm_, d);
    for (int i = 0; i < N; ++i) {
      s.x[i] = r.x[i];
      s.v[i] = v(i);
      s.acc[i] = acc(i);
      s.drift[i] = s.x[i] - (i ? s.x[i - 1] : 0.0);
    }
    s.acc[N - 1] = r.acc_top;
    s.elastic_energy = r.elastic_energy;
    if constexpr (kVines) {
      s.particle_x = r.particle_x;
      s.particle_v = r.particle_v;
      s.wall_left = s.x[dm_->floor] - dm_->dev.design.gap;
      s.wall_right = s.x[dm_->floor] + dm_->dev.design.gap;
      s.contact_force = r.contact_force;
      s.mode = static_cast<int>(r.mode);
    }
    if constexpr (kTmd) {
      s.tmd_x = d.z(N);
      s.tmd_v = d.z(2 * N + 1);
    }
    return s;
  }

  Probe probe() const override {
    Probe p;
    p.count = counters();
    p.ledger = ledger();
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
    if constexpr (kVines) r.max_overlap = static_cast<double>(fd_->max_depth) * nm_->step.cu.u.d;
    r.count = counters();
    r.ledger = ledger();
    r.fixed_saturations = saturations_;
    return r;
  }

  // The header (loop_state.hpp), then slots(): the node data a board holds
  // and what this engine keeps beside it.
  std::vector<std::uint8_t> state() const override { return loop_state::write(header(), slots()); }
  std::string load_state(const std::uint8_t* p, std::size_t n) override {
    std::string why = loop_state::check(header(), p, n);
    if (why.empty()) loop_state::read(p, slots());
    return why;
  }
  // The fixed step's state is scaled modes in Q3.28, its E_e and ledger its
  // own: not set from outside.
  std::string set_physical(const PhysicalState&) override {
    return "set_physical: not available in fixed point (loop.scalar = \"fixed\"); state() and load_state() are: "
           "run the scene in double or float to set a physical state";
  }
  std::string take_over(const Engine&) override {
    return "a change of model mid-run (a [damage] table) is not available in fixed point (loop.scalar = "
           "\"fixed\"): run the scene in double or float";
  }

 private:
  static constexpr std::size_t kStateBytes = sizeof(FD) + sizeof(Counters) + sizeof(fixed::SampleHold) +
                                             sizeof(std::int64_t) + sizeof(double) * (2 * N + 2);
  loop_state::Header header() const {
    return loop_state::header_of<N, Dev>(Scalar::kFixed, kStateBytes, fingerprint_.of(*this));
  }
  // Where the state's blocks live: the node data, counters, the sample hold,
  // saturations, the floors' peaks and drifts, the strain increments. Read by
  // state() (const), written by load_state().
  std::array<loop_state::Slot, 8> slots() const {
    auto& e = const_cast<FixedEngine&>(*this);
    return {{{e.fd_.get(), sizeof(FD)},
             {&e.count_, sizeof count_},
             {&e.hold_, sizeof hold_},
             {&e.saturations_, sizeof saturations_},
             {e.peaks_.data(), sizeof(double) * N},
             {e.drifts_.data(), sizeof(double) * N},
             {&e.strain_increments_, sizeof strain_increments_},
             {&e.last_strain_, sizeof last_strain_}}};
  }
  const auto& fm_frame() const { return Of::frame(nm_->step); }

  Q sample(double a) { return hold_.take<Q>(a, fm_frame().sa); }

  // The fixed state read back in double, in a Data of the double model (for
  // the double model's output functions): modes, particle, contact mode, and
  // the contact force the caller read [N].
  const DData& shadow(double contact_force = 0) const {
    DData& d = *shadow_;
    shadow_modes();
    if constexpr (kVines) {
      const FM& m = nm_->step;
      d.s = static_cast<double>(fd_->s) * m.length;
      d.sd = static_cast<double>(fd_->sd) * m.speed;
      d.xf = dm_->floor_x(d.z)(dm_->floor);
      const int side = fd_->side;
      d.mode = side < 0 ? Mode::kContactLeft : side > 0 ? Mode::kContactRight : Mode::kFree;
      d.contact_force = contact_force;
    }
    return d;
  }

  // The modes alone (a TMD: the frame and the TMD, z = T diag(u) y), in SI,
  // into the shadow Data.
  void shadow_modes() const {
    const auto& fd = Of::frame(*fd_);
    const auto& fr = fm_frame();
    if constexpr (kTmd) {
      Eigen::Matrix<double, 2 * P, 1> y;
      for (int k = 0; k < 2 * P; ++k) y(k) = static_cast<double>(fd.z(k));
      shadow_->z = fr.back * y;
    } else {
      constexpr int PF = std::decay_t<decltype(fr)>::kP;  // the fixed step's modes: the real ones
      shadow_->z.setZero();
      for (int j = 0; j < PF; ++j) {
        shadow_->z(j) = static_cast<double>(fd.z(j)) * fr.sq(j);
        shadow_->z(P + j) = static_cast<double>(fd.z(PF + j)) * fr.sv(j);
      }
    }
  }

  Ledger ledger() const {
    if (!nm_->ledger.on) return {};
    return Of::frame(*fd_).ledger.read(nm_->ledger.unit);
  }

  Counters counters() const {
    Counters c = count_;
    c.bad_samples = hold_.held;
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

  // The floors' peaks and drifts (the floors as the snapshot reads them) and
  // the positive strain increments (loop.floor_peaks).
  void floor_peaks() {
    const auto& z = Of::frame(*fd_).z;
    double below = 0;
    for (int i = 0; i < N; ++i) {
      const double x = fixed::floor_x(nm_->read, z, i);
      peaks_(i) = std::fmax(peaks_(i), std::fabs(x));
      drifts_(i) = std::fmax(drifts_(i), std::fabs(x - below));
      below = x;
    }
    shadow_modes();  // the strain needs the modes only, not the particle's contact force
    const double strain = dm_->strain.eval(shadow_->z, 0.0);
    if (strain > last_strain_) strain_increments_ += strain - last_strain_;
    last_strain_ = strain;
  }

  // Heap on the host (the blocks can be large); the firmware keeps them static.
  std::unique_ptr<DModel> dm_ = std::make_unique<DModel>();
  std::unique_ptr<NM> nm_ = std::make_unique<NM>();
  std::unique_ptr<FD> fd_ = std::make_unique<FD>();
  std::unique_ptr<DData> shadow_ = std::make_unique<DData>();
  loop_state::Fingerprint fingerprint_;  // of nm_ (loop states name it)
  FixedParams fixed_;
  Counters count_;
  fixed::SampleHold hold_;
  std::int64_t saturations_ = 0;
  Eigen::Matrix<double, N, 1> peaks_ = Eigen::Matrix<double, N, 1>::Zero(), drifts_ = peaks_;
  double strain_increments_ = 0, last_strain_ = 0;
};

}  // namespace vines::host
