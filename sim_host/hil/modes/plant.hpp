// The plant a host node runs (the firmware node's Plant, link/node.hpp): the
// scene's compiled firmware instance (replay mode, twin without estimator),
// the twin estimator (twin mode, estimator kalman: link/twin_plant.hpp), or
// the bare frame with the table's measured force (hybrid mode), chosen at
// configure.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "sim_host/engines/engine.hpp"
#include "vines/link/config.hpp"
#include "vines/link/hybrid_frame.hpp"
#include "vines/link/messages.hpp"
#include "vines/link/twin_plant.hpp"

namespace vines::host {

// The hybrid frame image (link/hybrid_frame.hpp) of the bare frame's modes
// at period h: what a hybrid node runs.
std::vector<std::uint8_t> hybrid_image(const ModelInfo& info, double h);

// The model image (model_image.hpp, or in hybrid mode the hybrid frame
// image) is collected as it arrives and loaded at configure: the host node,
// like a board, runs the model the bench built.
class HostPlant {
 public:
  const char* image_begin(std::uint32_t total);
  const char* image_push(const std::uint8_t* p, std::size_t n);
  const char* image_finish() { return nullptr; }  // checked at configure, by the engine
  bool configure(const link::NodeConfig& c, char* msg, std::size_t cap);
  // A whole image then the settings, as a session sends them (offline runs,
  // tests): false with the reason in msg if either is refused.
  bool load(const std::vector<std::uint8_t>& image, const link::NodeConfig& c, char* msg, std::size_t cap);
  void sense(const double* y, int ny) {
    if (twin_) twin_->sense(y, ny);
  }
  void init(double a0, double f0);
  void step(double a1, double f1);
  void read(link::Telemetry* t);

 private:
  std::vector<std::uint8_t> image_;
  link::NodeMode mode_ = link::NodeMode::kReplay;
  int n_ = 0;
  std::unique_ptr<Engine> engine_;
  link::HybridFrame<double> hybrid_;
  std::unique_ptr<link::TwinPlant<double, kMaxStories>> twin_;  // twin estimator (null otherwise)
  long long guard_events_ = 0;  // core guard counters at the last read
  bool tmd_mass_ = false;       // telemetry's particle_x/v: the TMD's mass (double, float)
};

}  // namespace vines::host
