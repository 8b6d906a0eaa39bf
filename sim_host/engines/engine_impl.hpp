// The Engine for one (scalar, story count, device): a thin host wrapper that
// owns a Model and a Data block and copies outputs out in double.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/LU>

#include "sim_host/engines/engine.hpp"
#include "sim_host/engines/loop_state.hpp"
#include "sim_host/engines/model_info.hpp"
#include "vines/build/build_model.hpp"
#include "vines/image/model_image.hpp"
#include "vines/step/set_state.hpp"
#include "vines/step/sim.hpp"

namespace vines::host {

template <typename S, int N, typename Dev>
class EngineImpl final : public Engine {
  using M = Model<S, N, Dev>;
  using D = Data<S, N, Dev>;
  // state() and load_state() copy the data block as bytes: it holds plain
  // members and fixed-size Eigen matrices (values in place), no pointer,
  // nothing it owns or must release, no virtual table. (Eigen's matrices
  // have copy constructors, so the type is not trivially copyable in the
  // standard's sense; byte copies of them are what Eigen's own copies do.)
  static_assert(!std::is_polymorphic_v<D> && std::is_trivially_destructible_v<D> &&
                    M::VecX::SizeAtCompileTime != Eigen::Dynamic && M::VecN::SizeAtCompileTime != Eigen::Dynamic,
                "Data must be copyable as bytes");
  static constexpr Scalar kScalar = std::is_same_v<S, float> ? Scalar::kFloat : Scalar::kDouble;

 public:
  ParamError build(const SceneParams& p) override {
    fingerprint_.forget();
    return build_model(p, model_.get());
  }
  ParamError set_initial_conditions(const SceneParams& p) override {
    fingerprint_.forget();
    return vines::set_initial_conditions(p.device, model_.get());
  }

  std::vector<std::uint8_t> model_image() const override {
    std::vector<std::uint8_t> out(image::image_bytes<S, N, Dev>());
    out.resize(image::write_image(*model_, out.data(), out.size()));
    return out;
  }

  std::string load_image(const std::uint8_t* p, std::size_t n) override {
    // Into a fresh model, kept only if the image is accepted.
    auto fresh = std::make_unique<Model<S, N, Dev>>();
    image::Loader<S, N, Dev> loader(fresh.get());
    const char* why = loader.push(p, n);
    if (!why) why = loader.finish();
    if (why) return why;
    model_ = std::move(fresh);
    fingerprint_.forget();
    return {};
  }

  ModelInfo info() const override { return model_info(*model_); }

  void init(double a0) override { vines::init(*model_, *data_, static_cast<S>(a0)); }
  void step(double a1) override { vines::step(*model_, *data_, static_cast<S>(a1)); }
  void run(const double* a, std::size_t n) override { vines::run(*model_, *data_, a, n); }

  Snapshot snapshot() const override {
    const Model<S, N, Dev>& m = *model_;
    const Data<S, N, Dev>& d = *data_;
    Snapshot s;
    s.t = d.time(m);
    s.ag = static_cast<double>(d.a_prev);
    const auto acc = absolute_accel(m, d);
    const auto x = floor_displacements(m, d), v = floor_velocities(m, d);
    for (int i = 0; i < N; ++i) {
      s.x[i] = static_cast<double>(x(i));
      s.v[i] = static_cast<double>(v(i));
      s.acc[i] = static_cast<double>(acc(i));
      s.drift[i] = s.x[i] - (i ? s.x[i - 1] : 0.0);
    }
    s.elastic_energy = elastic_energy(m, d);
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      const auto& dm = m.dev;
      s.particle_x = static_cast<double>(dm.y0 + d.s);
      s.particle_v = static_cast<double>(d.sd);
      const double xf = s.x[m.floor], gap = dm.design.gap;
      s.wall_left = xf - gap;
      s.wall_right = xf + gap;
      s.contact_force = static_cast<double>(d.contact_force);
      s.mode = static_cast<int>(d.mode);
    }
    if constexpr (Dev::kKind == DeviceKind::kTmd) {
      s.tmd_x = static_cast<double>(d.z(N));
      s.tmd_v = static_cast<double>(d.z(2 * N + 1));
    }
    return s;
  }

  Probe probe() const override {
    const Model<S, N, Dev>& m = *model_;
    const Data<S, N, Dev>& d = *data_;
    Probe p;
    p.count = d.count;
    p.ledger = energy_ledger(d);
    p.peak_top = static_cast<double>(d.peak_top);
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      const S r = d.s - d.xf;
      p.mode = static_cast<int>(d.mode);
      p.overlap = static_cast<double>(std::fmax(m.dev.wall_left - r, r - m.dev.wall_right));
    }
    return p;
  }

  RunTotals totals() const override {
    const Data<S, N, Dev>& d = *data_;
    RunTotals r;
    for (int i = 0; i < N; ++i) {
      r.peak_x[i] = static_cast<double>(d.peak_x(i));
      r.peak_drift[i] = static_cast<double>(d.peak_drift(i));
    }
    r.peak_top = static_cast<double>(d.peak_top);
    r.peak_x[N - 1] = r.peak_x[N - 1] > r.peak_top ? r.peak_x[N - 1] : r.peak_top;
    r.t_peak_top = peak_top_time(*model_, d);
    r.peak_top_velocity = static_cast<double>(d.peak_top_velocity);
    r.elastic_energy = elastic_energy(*model_, d);
    r.strain_increments = d.strain_increments.wide();
    r.max_overlap = static_cast<double>(d.max_overlap);
    r.ledger = energy_ledger(d);
    r.count = d.count;
    return r;
  }

  // The header (loop_state.hpp) and the data block.
  std::vector<std::uint8_t> state() const override { return loop_state::write(header(), slots()); }

  std::string load_state(const std::uint8_t* p, std::size_t n) override {
    std::string why = loop_state::check(header(), p, n);
    if (why.empty()) loop_state::read(p, slots());
    return why;
  }

  // The floors solved for the position (velocity) coordinates in double:
  // pos_map's first N columns (the mode shapes in modal form, the identity
  // in the TMD's physical form), LU; then vines::set_state in S.
  std::string set_physical(const PhysicalState& ps) override {
    const M& m = *model_;
    constexpr int P = M::kP;
    typename M::VecX z = data_->z;
    std::string why = solve_floors(ps.x, "x", 0, &z);
    if (why.empty()) why = solve_floors(ps.v, "v", P, &z);
    if (!why.empty()) return why;
    // One of the device's quantities into *to, if given.
    const auto take = [&](double value, const char* name, bool has, S* to, double offset = 0) -> std::string {
      if (std::isnan(value)) return {};
      if (!has) return std::string(name) + ": this model has no such device (leave it NaN)";
      if (!std::isfinite(value)) return std::string(name) + ": not finite";
      *to = static_cast<S>(value - offset);
      return {};
    };
    constexpr bool kTmd = Dev::kKind == DeviceKind::kTmd, kVines = Dev::kKind == DeviceKind::kVines;
    S tx = z(P - 1), tv = z(2 * P - 1), s = data_->s, sd = data_->sd;
    double y0 = 0;
    if constexpr (kVines) y0 = static_cast<double>(m.dev.y0);
    for (const std::string& w : {take(ps.tmd_x, "tmd_x", kTmd, &tx), take(ps.tmd_v, "tmd_v", kTmd, &tv),
                                 take(ps.particle_x, "particle_x", kVines, &s, y0),
                                 take(ps.particle_v, "particle_v", kVines, &sd)})
      if (!w.empty()) return w;
    if constexpr (kTmd) {
      z(N) = tx;
      z(2 * N + 1) = tv;
    }
    if constexpr (kVines) {
      const S xf = m.dev_x(z);
      if (!particle_clear(m, s, xf)) {
        const double at = static_cast<double>(xf), gap = m.dev.design.gap;
        char msg[256];
        std::snprintf(msg, sizeof msg,
                      "particle_x: %.9g m is not strictly between the walls (%.9g m and %.9g m, where the "
                      "centre touches them, the device floor at %.9g m)",
                      y0 + static_cast<double>(s), at - gap, at + gap, at);
        return msg;
      }
    }
    const char* refused = vines::set_state(m, *data_, z, s, sd);
    return refused ? refused : std::string();
  }

  // The data block of `from` (same engine, another model), then the floors
  // it holds solved for this model's coordinates (a TMD's physical form: the
  // same z), E_e's open run closed as `from` reads it, the ledger's jump.
  std::string take_over(const Engine& from) override {
    const std::vector<std::uint8_t> st = from.state();
    std::string why = loop_state::check(header(), st.data(), st.size(), true);
    if (!why.empty()) return "cannot take over the run: " + why;
    const ModelInfo mine = info(), theirs = from.info();
    if (theirs.sensor_period != mine.sensor_period || theirs.device_floor != mine.device_floor ||
        theirs.tmd.mass != mine.tmd.mass || theirs.tmd.k != mine.tmd.k || theirs.tmd.c != mine.tmd.c ||
        theirs.vines.mass != mine.vines.mass || theirs.vines.gap != mine.vines.gap)
      return "cannot take over the run: the models differ in more than the frame (sensor period or device)";
    const M& m = *model_;
    auto d = std::make_unique<D>();
    loop_state::read(st.data(), std::array<loop_state::Slot, 1>{{{d.get(), sizeof(D)}}});
    const Snapshot now = from.snapshot();
    typename M::VecX z = d->z;
    why = solve_floors(now.x, "x", 0, &z);
    if (why.empty()) why = solve_floors(now.v, "v", M::kP, &z);
    if (!why.empty()) return "cannot take over the run: " + why;
    if (!z.allFinite()) return "cannot take over the run: the state is not finite";
    // E_e so far, closed on from's model (its open run ends here).
    const double ee = now.elastic_energy;
    d->ee_sum = {};
    d->ee_sum.add(static_cast<S>(ee));
    d->ee_sum.add(static_cast<S>(ee - static_cast<double>(static_cast<S>(ee))));
    d->ee_open = false;
    const bool ledger = m.loop.energy_ledger;
    const S before = d->ledger.kinetic + d->ledger.strain + d->ledger.device;  // from's, closed by its last step
    d->z = z;
    vines::detail::refresh_floors(m, *d);
    d->last_strain = m.strain.eval(d->z, S(0));
    if (ledger) {
      d->ledger.initial += vines::detail::stored_energy(m, *d) - before;
      vines::detail::close_ledger(m, *d);
    }
    data_ = std::move(d);
    return {};
  }

 private:
  // Floors f (NaN: all or none) solved for the position (velocity)
  // coordinates z[at..at+N) in double: pos_map's first N columns (the mode
  // shapes in modal form, the identity in the TMD's physical form), LU.
  std::string solve_floors(const FloorArray& f, const char* name, int at, typename M::VecX* z) const {
    int given = 0;
    for (int i = 0; i < N; ++i) given += std::isnan(f[i]) ? 0 : 1;
    if (given == 0) return {};
    Eigen::Matrix<double, N, 1> b;
    for (int i = 0; i < N; ++i) {
      if (std::isnan(f[i]))
        return std::string(name) + ": give all " + std::to_string(N) + " floors or none (floor " +
               std::to_string(i + 1) + " is NaN, " + std::to_string(given) + " are not)";
      if (!std::isfinite(f[i])) return std::string(name) + ": floor " + std::to_string(i + 1) + " is not finite";
      b(i) = f[i];
    }
    const Eigen::Matrix<double, N, N> map = model_->pos_map.template leftCols<N>().template cast<double>();
    const Eigen::PartialPivLU<Eigen::Matrix<double, N, N>> lu(map);
    z->template segment<N>(at) = lu.solve(b).template cast<S>();
    return {};
  }

  std::array<loop_state::Slot, 1> slots() const { return {{{data_.get(), sizeof(D)}}}; }
  loop_state::Header header() const {
    return loop_state::header_of<N, Dev>(kScalar, sizeof(D), fingerprint_.of(*this));
  }

  // Heap on the host (the blocks can be large); the firmware keeps them static.
  std::unique_ptr<Model<S, N, Dev>> model_ = std::make_unique<Model<S, N, Dev>>();
  std::unique_ptr<Data<S, N, Dev>> data_ = std::make_unique<Data<S, N, Dev>>();
  loop_state::Fingerprint fingerprint_;  // of model_ (loop states name it)
};

}  // namespace vines::host
