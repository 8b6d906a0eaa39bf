// What the bench computes in its own process: the model image it sends the
// node, and the offline run the node's telemetry is compared with.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vines/link/config.hpp"
#include "vines/link/messages.hpp"

namespace vines::host {

// The model image of a node's configuration (model_image.hpp; in hybrid
// mode the hybrid frame image of the bare frame, link/hybrid_frame.hpp): what
// the bench sends so that no node builds a model. Errors name `what`.
std::vector<std::uint8_t> model_image(const link::NodeConfig& cfg, const std::string& what);

// The offline run: the scene's engine stepped in this process, read exactly
// as the node reads it (HostPlant), so equal code gives equal bits. With
// `starts` (a restarted node's first samples, ascending), a fresh plant from
// rest at each, as the restarted node does: the clean run of each node life.
// A twin estimator's run needs what the node gets beyond the configuration:
// its twin image and each sample's measured floor accelerations.
struct TwinInputs {
  const std::vector<std::uint8_t>* image = nullptr;
  const std::vector<std::vector<double>>* measured = nullptr;
};
std::vector<link::Telemetry> offline_run(const link::NodeConfig& cfg, const std::vector<double>& samples,
                                         const std::string& what, const std::vector<long long>& starts = {},
                                         const TwinInputs& twin = {});

}  // namespace vines::host
