// The plant of a board's node (link/node.hpp): one compiled instance of the
// core (scalar S, N stories, device Dev) whose model arrives as the image the
// host built (model_image.hpp), decoded straight into static storage, for
// replay mode and the open-loop twin; in hybrid mode the bare frame driven by
// the table's force (link/hybrid_frame.hpp), whose discretised modes arrive
// as the hybrid frame image instead. The twin with an estimator is another
// image's (twin_plant.hpp, firmware/app/twin_main.cpp). The board never
// builds a model: no eigensolver, no matrix exponential.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vines/image/model_image.hpp"
#include "vines/link/config.hpp"
#include "vines/link/hybrid_frame.hpp"
#include "vines/link/messages.hpp"
#include "vines/link/status_text.hpp"
#include "vines/step/sim.hpp"
#include "vines/twin/image.hpp"

namespace vines::link {

template <typename S, int N, typename Dev>
class ModelPlant {
 public:
  using ModelT = Model<S, N, Dev>;
  using DataT = Data<S, N, Dev>;

  // model and data: static storage of the application (they are large).
  ModelPlant(ModelT* model, DataT* data) : model_(model), data_(data), loader_(model) {}

  // The image: a core model image, streamed into the model, or a hybrid
  // frame image (told by its magic), gathered and then loaded.
  const char* image_begin(std::uint32_t total) {
    configured_ = false;
    hybrid_ready_ = false;
    loader_.reset();
    image_total_ = total;
    image_len_ = 0;
    return nullptr;
  }
  const char* image_push(const std::uint8_t* p, std::size_t n) {
    if (image_len_ == 0) {
      hybrid_image_ = is_hybrid_image(p, n);
      if (twin::is_twin_image(p, n)) return kNoEstimator;
    }
    if (!hybrid_image_) {
      image_len_ += n;
      return loader_.push(p, n);
    }
    if (image_total_ > sizeof hybrid_buf_ || n > sizeof hybrid_buf_ - image_len_)
      return "hybrid frame image: more stories than this board holds";
    std::memcpy(hybrid_buf_ + image_len_, p, n);
    image_len_ += n;
    return nullptr;
  }
  const char* image_finish() {
    if (!hybrid_image_) return loader_.finish();
    const char* why = hybrid_.load(hybrid_buf_, image_len_, N);
    hybrid_ready_ = why == nullptr;
    return why;
  }

  // The settings must fit the image this node holds.
  bool configure(const NodeConfig& c, char* msg, std::size_t cap) {
    configured_ = false;
    const char* why = check(c);
    if (why) {
      copy_text(why, msg, cap);
      return false;
    }
    configured_ = true;
    hybrid_mode_ = c.mode == NodeMode::kHybrid;
    guard_events_ = 0;
    return true;
  }

  void sense(const double*, int) {}  // the open-loop twin reads no floor
  void init(double a0, double f0) {
    guard_events_ = 0;
    if (hybrid_mode_) hybrid_.init(a0, f0);
    else vines::init(*model_, *data_, static_cast<S>(a0));
  }
  void step(double a1, double f1) {
    if (hybrid_mode_) hybrid_.step(a1, f1);
    else vines::step(*model_, *data_, static_cast<S>(a1));
  }

  // What the host node's plant reads (sim_host/hil/modes/plant.cpp), from the same
  // core functions.
  void read(Telemetry* t) {
    if (hybrid_mode_) {
      t->n = static_cast<std::uint8_t>(N);
      for (int i = 0; i < N; ++i) t->x[i] = hybrid_.x(i);
      t->acc_top = hybrid_.abs_acc(N - 1);
      t->elastic_energy = hybrid_.elastic_energy();
      return;
    }
    const ModelT& m = *model_;
    const DataT& d = *data_;
    const auto x = floor_displacements(m, d);
    const auto acc = absolute_accel(m, d);
    t->n = static_cast<std::uint8_t>(N);
    for (int i = 0; i < N; ++i) t->x[i] = static_cast<double>(x(i));
    t->acc_top = static_cast<double>(acc(N - 1));
    t->elastic_energy = elastic_energy(m, d);
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      t->particle_x = static_cast<double>(m.dev.y0 + d.s);
      t->particle_v = static_cast<double>(d.sd);
      t->contact_force = static_cast<double>(d.contact_force);
      t->contact_mode = static_cast<std::uint8_t>(d.mode);
    }
    if constexpr (Dev::kKind == DeviceKind::kTmd) {
      // z = [x_1..x_N, x_d; v_1..v_N, v_d] (lti.hpp, DenseLti).
      t->particle_x = static_cast<double>(d.z(N));
      t->particle_v = static_cast<double>(d.z(2 * N + 1));
    }
    t->dissipated = d.ledger.contact.wide();
    const std::int64_t guards = d.count.bad_samples + d.count.divergences;
    if (guards != guard_events_) t->flags |= kGuard;
    guard_events_ = guards;
  }

  bool configured() const { return configured_; }

 private:
  const char* check(const NodeConfig& c) const {
    if (c.scalar != (sizeof(S) == 4 ? 1 : 0))
      return sizeof(S) == 4 ? "scalar: this node runs float" : "scalar: this node runs double";
    if (c.mode == NodeMode::kTwin && c.estimator == TwinEstimator::kKalman)
      return kNoEstimator;
    if (c.mode == NodeMode::kHybrid) {
      if (!hybrid_ready_) return "mode hybrid: send a hybrid frame image before the settings";
      if (c.scene.frame.stories != N || hybrid_.stories() != N) return "frame.stories: differs from this board's";
      if (!(std::fabs(hybrid_.period() * c.scene.loop.sensor_rate_hz - 1.0) <= 1e-12))
        return "loop.sensor_rate_hz: differs from the hybrid frame image's";
      return nullptr;
    }
    if (!loader_.ready()) return "no model image: send it before the settings";
    if (c.scene.frame.stories != N) return "frame.stories: differs from the model image's";
    if (c.scene.device.kind != Dev::kKind) return "device.kind: differs from the model image's";
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      if (c.scene.device.vines.law != Dev::kLaw) return "vines.law: differs from the model image's";
    }
    const double rate = c.scene.loop.sensor_rate_hz;
    if (!(std::fabs(model_->h * rate - 1.0) <= 1e-12))
      return "loop.sensor_rate_hz: differs from the model image's";
    if (c.scene.loop.contact_scheme != model_->loop.contact_scheme)
      return "loop.contact_scheme: differs from the model image's";
    if (c.scene.loop.bounded_substeps != model_->loop.bounded_substeps)
      return "loop.bounded_substeps: differs from the model image's";
    if (c.scene.loop.split_steps != model_->loop.split_steps)
      return "loop.split_steps: differs from the model image's";
    return nullptr;
  }

  static constexpr const char* kNoEstimator =
      "estimator kalman: this image holds no estimator (the twin image vines_node_twin.elf does)";

  ModelT* model_;
  DataT* data_;
  image::Loader<S, N, Dev> loader_;
  HybridFrame<S> hybrid_;
  std::uint8_t hybrid_buf_[hybrid_image_bytes(N)] = {};
  std::size_t image_total_ = 0, image_len_ = 0;
  bool hybrid_image_ = false, hybrid_ready_ = false, hybrid_mode_ = false;
  bool configured_ = false;
  std::int64_t guard_events_ = 0;
};

}  // namespace vines::link
