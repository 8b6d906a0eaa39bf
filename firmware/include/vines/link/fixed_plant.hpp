// The plant of a fixed-point node (link/node.hpp; issue 34): one compiled
// instance of the Q3.28 model (fixed/node_model.hpp: N stories, device
// Dev) whose model arrives as the fixed-point model image the host built
// (fixed/image.hpp), streamed straight into static storage. Replay and the
// open-loop twin; no estimator, no hybrid mode. Its step has no floating
// point; a sample's conversion and the telemetry are double, in software
// on an FPU-less core, the same operations as the host's fixed-point engine
// (sim_host/engines/fixed_engine.hpp): the board and the host agree bit for
// bit.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "vines/fixed/node_model.hpp"
#include "vines/link/config.hpp"
#include "vines/link/messages.hpp"
#include "vines/link/status_text.hpp"
#include "vines/numeric/fixed.hpp"

namespace vines::link {

template <int N, typename Dev>
class FixedPlant {
 public:
  using ModelT = fixed::NodeModel<N, Dev>;
  using DataT = typename ModelT::D;
  using Q = typename ModelT::Q;

  // model and data: static storage of the application.
  FixedPlant(ModelT* model, DataT* data)
      : model_(model), data_(data), loader_(fixed::image_kind<N, Dev>(), model) {}

  const char* image_begin(std::uint32_t total) {
    configured_ = false;
    loader_.reset();
    if (total != fixed::kImageHeaderBytes + sizeof(ModelT))
      return "model image: not this node's (it runs a Q3.28 model: loop.scalar = \"fixed\", its device and stories)";
    return nullptr;
  }
  const char* image_push(const std::uint8_t* p, std::size_t n) { return loader_.push(p, n); }
  const char* image_finish() { return loader_.finish(); }

  bool configure(const NodeConfig& c, char* msg, std::size_t cap) {
    const char* why = check(c);
    if (why) copy_text(why, msg, cap);
    configured_ = why == nullptr;
    return configured_;
  }

  void sense(const double*, int) {}  // the open-loop twin reads no floor
  void init(double a0, double /*f0*/) {
    saturations_ = numeric::fixed_saturations();
    hold_ = fixed::SampleHold{};
    guard_events_ = 0;
    fixed::node_init(*model_, *data_, sample(a0));
  }
  void step(double a1, double /*f1*/) { fixed::node_step(*model_, *data_, sample(a1)); }

  // What the host's fixed-point engine reports (snapshot): fixed::read_node.
  void read(Telemetry* t) {
    const fixed::NodeReading<N> r = fixed::read_node(*model_, *data_);
    t->n = static_cast<std::uint8_t>(N);
    for (int i = 0; i < N; ++i) t->x[i] = r.x[i];
    t->acc_top = r.acc_top;
    t->elastic_energy = r.elastic_energy;
    t->particle_x = r.particle_x;
    t->particle_v = r.particle_v;
    t->contact_force = r.contact_force;
    t->contact_mode = static_cast<std::uint8_t>(r.mode);
    t->dissipated = r.dissipated;
    // A held sample or a saturation: the run is degraded from here.
    const std::uint32_t guards = hold_.held + (numeric::fixed_saturations() - saturations_);
    if (guards != guard_events_) t->flags |= kGuard;
    guard_events_ = guards;
  }

  bool configured() const { return configured_; }

 private:
  Q sample(double a) { return hold_.take<Q>(a, ModelT::Step::frame(model_->step).sa); }

  const char* check(const NodeConfig& c) const {
    if (c.scalar != 2) return "scalar: this node runs Q3.28 fixed point (loop.scalar = \"fixed\")";
    if (c.mode == NodeMode::kHybrid) return "mode hybrid: this node runs a fixed-point model (replay or twin only)";
    if (c.mode == NodeMode::kTwin && c.estimator == TwinEstimator::kKalman)
      return "estimator kalman: this image holds no estimator (the twin image vines_node_twin.elf does)";
    if (!loader_.ready()) return "no model image: send it before the settings";
    if (c.scene.frame.stories != N) return "frame.stories: differs from the model image's";
    if (c.scene.device.kind != Dev::kKind) return "device.kind: differs from the model image's";
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      if (c.scene.device.vines.law != Dev::kLaw) return "vines.law: differs from the model image's";
      if (c.scene.loop.contact_scheme != ContactScheme::kSplit)
        return "loop.contact_scheme: a fixed-point node runs \"split\"";
      if (c.scene.loop.split_steps != model_->split_steps) return "loop.split_steps: differs from the model image's";
    }
    if (!(std::fabs(model_->h * c.scene.loop.sensor_rate_hz - 1.0) <= 1e-12))
      return "loop.sensor_rate_hz: differs from the model image's";
    if (c.scene.loop.energy_ledger != model_->ledger.on) return "loop.energy_ledger: differs from the model image's";
    return nullptr;
  }

  ModelT* model_;
  DataT* data_;
  fixed::ImageLoader loader_;
  fixed::SampleHold hold_;
  std::uint32_t saturations_ = 0, guard_events_ = 0;
  bool configured_ = false;
};

}  // namespace vines::link
