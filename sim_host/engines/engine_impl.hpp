// The Engine for one (scalar, story count, device): a thin host wrapper that
// owns a Model and a Data block and copies outputs out in double.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sim_host/engines/engine.hpp"
#include "sim_host/engines/model_info.hpp"
#include "vines/build_model.hpp"
#include "vines/model_image.hpp"
#include "vines/sim.hpp"

namespace vines::host {

template <typename S, int N, typename Dev>
class EngineImpl final : public Engine {
 public:
  ParamError build(const SceneParams& p) override { return build_model(p, model_.get()); }
  ParamError set_initial_conditions(const SceneParams& p) override {
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

 private:
  // Heap on the host (the blocks can be large); the firmware keeps them static.
  std::unique_ptr<Model<S, N, Dev>> model_ = std::make_unique<Model<S, N, Dev>>();
  std::unique_ptr<Data<S, N, Dev>> data_ = std::make_unique<Data<S, N, Dev>>();
};

}  // namespace vines::host
