// `vines reference`: a scene and its bare frame integrated by the reference
// at two tolerances (its own convergence check), as one JSON document.
#pragma once

#include <nlohmann/json.hpp>

#include "sim_host/scene.hpp"

namespace vines::host::reference {

// rtol 0: the reference default. The coarse run uses 100 * rtol. Throws
// std::runtime_error naming the input on any problem.
nlohmann::json reference_report(const Scene& scene, double rtol);

}  // namespace vines::host::reference
