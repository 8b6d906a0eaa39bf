// Scenes as toml++ tables, for code that edits a scene before checking it
// (study overrides, written stress cases): the same checks and messages as
// load_scene / parse_scene, which go through these. Kept apart from
// scene.hpp so that most of the host does not compile toml++.
#pragma once

#include <toml++/toml.h>

#include <string>

#include "sim_host/scene/scene.hpp"

namespace vines::host {

// The scene file's table; SceneError if it cannot be read or is not TOML.
toml::table read_scene_table(const std::string& path);

// TOML text as a table; `origin` names it in messages.
toml::table parse_scene_table(const std::string& toml_text, const std::string& origin);

// The checked Scene of a table (unknown keys, types, values: SceneError
// naming `origin`, and the key's line when it came from a file).
Scene scene_from_table(const toml::table& root, const std::string& origin);

}  // namespace vines::host
