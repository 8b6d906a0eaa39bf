#include "sim_host/hil/offline.hpp"

#include <memory>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/hil/modes/plant.hpp"
#include "sim_host/run/drive.hpp"

namespace vines::host {
namespace {

// A host node's plant fed as drive() feeds an engine; offline, the table
// force is 0.
struct OfflineFeed {
  HostPlant& plant;
  void init(double a) { plant.init(a, 0); }
  void run(const double* a, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) plant.step(a[i], 0);
  }
};

}  // namespace

std::vector<std::uint8_t> model_image(const link::NodeConfig& cfg, const std::string& what) {
  const Scalar scalar = scalar_of_code(cfg.scalar);
  if (cfg.mode != link::NodeMode::kHybrid) return build_engine(cfg.scene, scalar, what)->model_image();
  // Hybrid: the bare frame's modes (the device is on the table).
  SceneParams bare = cfg.scene;
  bare.device.kind = DeviceKind::kNone;
  return hybrid_image(build_engine(bare, Scalar::kDouble, what)->info(), 1.0 / bare.loop.sensor_rate_hz);
}

std::vector<link::Telemetry> offline_run(const link::NodeConfig& cfg, const std::vector<double>& samples,
                                         const std::string& what, const std::vector<long long>& starts,
                                         const TwinInputs& twin) {
  const std::vector<std::uint8_t> image = twin.image ? *twin.image : model_image(cfg, what);
  const std::vector<std::vector<double>>* measured = twin.measured;
  std::vector<link::Telemetry> out(samples.size());
  const auto n = static_cast<long long>(samples.size());
  // One life from each start (the first at 0) to the next: a fresh plant.
  std::vector<long long> from = {0};
  for (long long k : starts)
    if (k > from.back() && k < n) from.push_back(k);
  from.push_back(n);
  for (std::size_t i = 0; i + 1 < from.size(); ++i) {
    HostPlant plant;
    char msg[64] = {};
    if (!plant.load(image, cfg, msg, sizeof msg)) throw std::runtime_error(what + ": " + msg);
    const auto sense = [&](std::size_t k) {
      if (measured) plant.sense((*measured)[k].data(), static_cast<int>((*measured)[k].size()));
    };
    const auto k0 = static_cast<std::size_t>(from[i]), k1 = static_cast<std::size_t>(from[i + 1]);
    OfflineFeed feed{plant};
    hal::RecordSource src(samples.data() + k0, k1 - k0, cfg.scene.loop.sensor_rate_hz);
    sense(k0);
    drive(feed, src, 1, [&](std::size_t j) {
      plant.read(&out[k0 + j]);
      if (k0 + j + 1 < k1) sense(k0 + j + 1);  // the floors measured at the next sample
    });
  }
  return out;
}

}  // namespace vines::host
