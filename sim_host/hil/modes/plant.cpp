#include "sim_host/hil/modes/plant.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "sim_host/engines/build_engine.hpp"
#include "vines/build/lti_build.hpp"

namespace vines::host {
namespace {

// The modal data of a bare frame, from a built engine's model info.
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

}  // namespace

std::vector<std::uint8_t> hybrid_image(const ModelInfo& info, double h) {
  const link::ModalData md = modal_data(info);
  link::ModeStep steps[kMaxStories];
  for (int j = 0; j < md.n; ++j) {
    const double w = md.omega[j], z = md.zeta[j];
    Eigen::Matrix2d a;
    a << 0, 1, -w * w, -2 * z * w;
    // The core loop's exact FOH step, with the modal input u as the input.
    const detail::Foh<2> f = detail::foh<2>(a, Eigen::Vector2d(0, 1), h);
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 2; ++c) steps[j].a[r][c] = f.phi(r, c);
      steps[j].g0[r] = f.g0(r);
      steps[j].g1[r] = f.g1(r);
    }
  }
  std::vector<std::uint8_t> out(link::hybrid_image_bytes(md.n));
  out.resize(link::write_hybrid_image(md, steps, h, out.data(), out.size()));
  return out;
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

bool HostPlant::load(const std::vector<std::uint8_t>& image, const link::NodeConfig& c, char* msg,
                     std::size_t cap) {
  if (const char* why = image_begin(static_cast<std::uint32_t>(image.size()))) {
    std::snprintf(msg, cap, "%s", why);
    return false;
  }
  image_push(image.data(), image.size());
  return configure(c, msg, cap);
}

bool HostPlant::configure(const link::NodeConfig& c, char* msg, std::size_t cap) {
  mode_ = c.mode;
  n_ = c.scene.frame.stories;
  const auto refuse = [&](const std::string& why) {
    std::snprintf(msg, cap, "%s", why.c_str());
    return false;
  };
  if (image_.empty()) return refuse("no model image: send it before the settings");
  // Hybrid: the bare frame's modes, discretised by the bench (hybrid_frame.hpp).
  if (mode_ == link::NodeMode::kHybrid) {
    if (!link::is_hybrid_image(image_.data(), image_.size()))
      return refuse("mode hybrid: the model image is not a hybrid frame image");
    if (const char* why = hybrid_.load(image_.data(), image_.size(), kMaxStories)) return refuse(why);
    if (hybrid_.stories() != n_) return refuse("frame.stories: differs from the hybrid frame image's");
    if (!(std::fabs(hybrid_.period() * c.scene.loop.sensor_rate_hz - 1.0) <= 1e-12))
      return refuse("loop.sensor_rate_hz: differs from the hybrid frame image's");
    return true;
  }
  twin_.reset();
  if (c.estimator == link::TwinEstimator::kKalman) {
    if (!twin::is_twin_image(image_.data(), image_.size()))
      return refuse("estimator kalman: the model image is not a twin image");
    twin_ = std::make_unique<link::TwinPlant<double, kMaxStories>>();
    twin_->image_begin();
    const char* why = twin_->image_push(image_.data(), image_.size());
    if (!why) why = twin_->image_finish();
    if (!why && twin_->configure(c, msg, cap)) return true;
    twin_.reset();
    return !why || refuse(why);
  }
  const Scalar scalar = scalar_of_code(c.scalar);
  // The TMD's mass as the boards' nodes send it (link/model_plant.hpp): in
  // double and float; the fixed-point node (fixed_plant.hpp) sends none.
  tmd_mass_ = c.scene.device.kind == DeviceKind::kTmd && scalar != Scalar::kFixed;
  try {
    engine_ = engine_for(c.scene, scalar, "node");
  } catch (const EngineError& e) {
    return refuse(e.reason());
  }
  const std::string why = engine_->load_image(image_.data(), image_.size());
  return why.empty() || refuse(why);
}

void HostPlant::init(double a0, double f0) {
  guard_events_ = 0;
  if (mode_ == link::NodeMode::kHybrid) hybrid_.init(a0, f0);
  else if (twin_) twin_->init(a0);
  else engine_->init(a0);
}

void HostPlant::step(double a1, double f1) {
  if (mode_ == link::NodeMode::kHybrid) hybrid_.step(a1, f1);
  else if (twin_) twin_->step(a1);
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
  if (twin_) return twin_->read(t);
  const Snapshot s = engine_->snapshot();
  const Probe p = engine_->probe();
  const int n = n_;
  t->n = static_cast<std::uint8_t>(n);
  for (int i = 0; i < n; ++i) t->x[i] = s.x[i];
  t->acc_top = s.acc[n - 1];
  t->elastic_energy = s.elastic_energy;
  t->particle_x = tmd_mass_ ? s.tmd_x : s.particle_x;
  t->particle_v = tmd_mass_ ? s.tmd_v : s.particle_v;
  t->contact_force = s.contact_force;
  t->contact_mode = static_cast<std::uint8_t>(s.mode);
  t->dissipated = p.ledger.contact;
  const long long guards = p.count.bad_samples + p.count.divergences;
  if (guards != guard_events_) t->flags |= link::kGuard;
  guard_events_ = guards;
}

}  // namespace vines::host
