#include "sim_host/hil_offline.hpp"

#include <memory>
#include <stdexcept>

#include "sim_host/build_engine.hpp"
#include "sim_host/hil_plant.hpp"

namespace vines::host {

std::vector<std::uint8_t> model_image(const link::NodeConfig& cfg, const std::string& what) {
  if (cfg.mode == link::NodeMode::kHybrid) return {};
  const Scalar scalar = cfg.scalar ? Scalar::kFloat : Scalar::kDouble;
  return build_engine(cfg.scene, scalar, what)->model_image();
}

std::vector<link::Telemetry> offline_run(const link::NodeConfig& cfg, const std::vector<double>& samples,
                                         const std::string& what) {
  HostPlant plant;
  char msg[64] = {};
  const std::vector<std::uint8_t> image = model_image(cfg, what);
  plant.image_begin(static_cast<std::uint32_t>(image.size()));
  plant.image_push(image.data(), image.size());
  if (!plant.configure(cfg, msg, sizeof msg)) throw std::runtime_error(what + ": " + msg);
  std::vector<link::Telemetry> out(samples.size());
  plant.init(samples[0], 0);
  plant.read(&out[0]);
  for (std::size_t k = 1; k < samples.size(); ++k) {
    plant.step(samples[k], 0);
    plant.read(&out[k]);
  }
  return out;
}

}  // namespace vines::host
