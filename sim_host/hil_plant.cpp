#include "sim_host/hil_plant.hpp"

#include <cstdio>
#include <string>

#include "sim_host/build_engine.hpp"

namespace vines::host {

link::ModalData modal_data(const ModelInfo& info) {
  link::ModalData md;
  md.n = info.stories;
  for (int j = 0; j < md.n; ++j) {
    md.omega[j] = 2 * M_PI * info.frequency_hz[j];
    md.zeta[j] = info.zeta[j];
    md.gamma[j] = info.gamma[j];
    // mode_shapes are phi_j * gamma_j; a shear frame's modes all participate.
    for (int i = 0; i < md.n; ++i) md.phi[i][j] = info.mode_shapes[j][i] / info.gamma[j];
  }
  return md;
}

// Far above any model image of the compiled frames (40 stories, double).
constexpr std::uint32_t kMaxImageBytes = 1u << 24;

const char* HostPlant::image_begin(std::uint32_t total) {
  image_.clear();
  if (total > kMaxImageBytes) return "model image: larger than any this node can hold";
  image_.reserve(total);
  return nullptr;
}

const char* HostPlant::image_push(const std::uint8_t* p, std::size_t n) {
  image_.insert(image_.end(), p, p + n);
  return nullptr;
}

bool HostPlant::configure(const link::NodeConfig& c, char* msg, std::size_t cap) {
  mode_ = c.mode;
  SceneParams p = c.scene;
  if (mode_ == link::NodeMode::kHybrid) p.device.kind = DeviceKind::kNone;  // the device is on the table
  const Scalar scalar = c.scalar ? Scalar::kFloat : Scalar::kDouble;
  // Hybrid nodes build the bare frame here; the others load the bench's image.
  const bool hybrid = mode_ == link::NodeMode::kHybrid;
  try {
    engine_ = hybrid ? build_engine(p, scalar, "node") : engine_for(p, scalar, "node");
  } catch (const EngineError& e) {
    std::snprintf(msg, cap, "%s", e.reason().c_str());
    return false;
  }
  if (!hybrid) {
    if (image_.empty()) {
      std::snprintf(msg, cap, "no model image: send it before the settings");
      return false;
    }
    const std::string why = engine_->load_image(image_.data(), image_.size());
    if (!why.empty()) {
      std::snprintf(msg, cap, "%s", why.c_str());
      return false;
    }
    n_ = p.frame.stories;
    return true;
  }
  n_ = p.frame.stories;
  hybrid_.setup(modal_data(engine_->info()), 1.0 / p.loop.sensor_rate_hz);
  return true;
}

void HostPlant::init(double a0, double f0) {
  guard_events_ = 0;
  if (mode_ == link::NodeMode::kHybrid) hybrid_.init(a0, f0);
  else engine_->init(a0);
}

void HostPlant::step(double a1, double f1) {
  if (mode_ == link::NodeMode::kHybrid) hybrid_.step(a1, f1);
  else engine_->step(a1);
}

void HostPlant::read(link::Telemetry* t) {
  if (mode_ == link::NodeMode::kHybrid) {
    t->n = static_cast<std::uint8_t>(hybrid_.stories());
    for (int i = 0; i < t->n; ++i) t->x[i] = hybrid_.x(i);
    t->acc_top = hybrid_.abs_acc(t->n - 1);
    t->elastic_energy = hybrid_.elastic_energy();
    return;
  }
  const Snapshot s = engine_->snapshot();
  const Probe p = engine_->probe();
  const int n = n_;
  t->n = static_cast<std::uint8_t>(n);
  for (int i = 0; i < n; ++i) t->x[i] = s.x[i];
  t->acc_top = s.acc[n - 1];
  t->elastic_energy = s.elastic_energy;
  t->particle_x = s.particle_x;
  t->particle_v = s.particle_v;
  t->contact_force = s.contact_force;
  t->contact_mode = static_cast<std::uint8_t>(s.mode);
  t->dissipated = p.ledger.contact;
  const long long guards = p.count.bad_samples + p.count.divergences;
  if (guards != guard_events_) t->flags |= link::kGuard;
  guard_events_ = guards;
}

}  // namespace vines::host
