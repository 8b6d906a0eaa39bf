// Where a scene's record file is: resolve_record_path (scene.hpp).
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "sim_host/scene/scene.hpp"

namespace vines::host {

// ---- record search: absolute as is; else cwd, scene folder, ground motions ----
std::string resolve_record_path(const std::string& record_path, const std::string& scene_path) {
  namespace fs = std::filesystem;
  if (record_path.empty()) throw SceneError(scene_path + ": record.path: empty");
  const fs::path p(record_path);
  std::vector<std::pair<fs::path, std::string>> tried;  // candidate, why it was tried
  if (p.is_absolute()) {
    tried.emplace_back(p, "absolute");
  } else {
    tried.emplace_back(p, "working directory");
    const fs::path dir = fs::path(scene_path).parent_path();
    if (!dir.empty()) tried.emplace_back(dir / p, "scene folder");
    const char* env = std::getenv("VINES_GROUND_MOTIONS");
    if (env != nullptr && *env != '\0') {
      tried.emplace_back(fs::path(env) / p, "$VINES_GROUND_MOTIONS");
    } else {
#ifdef VINES_DEFAULT_GROUND_MOTIONS
      tried.emplace_back(fs::path(VINES_DEFAULT_GROUND_MOTIONS) / p, "default ground motions");
#endif
    }
  }
  std::string list;
  for (const auto& [candidate, why] : tried) {
    std::error_code ec;
    const fs::file_type type = fs::status(candidate, ec).type();
    if (type == fs::file_type::regular) return fs::absolute(candidate).lexically_normal().string();
    // A folder, a device or a FIFO by that name: refused, not searched past.
    if (type != fs::file_type::not_found && type != fs::file_type::none)
      throw SceneError(scene_path + ": record.path: \"" + record_path + "\": " + candidate.string() + " (" + why +
                       ") is not a regular file (a folder, device or FIFO)");
    list += (list.empty() ? "" : ", ") + candidate.string() + " (" + why + ")";
  }
  throw SceneError(scene_path + ": record.path: \"" + record_path + "\" not found; tried " + list);
}

}  // namespace vines::host
