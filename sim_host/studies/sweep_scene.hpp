// A sweep run's scene: the study's toml++ table with the run's keys set, and
// the cache keys of what runs share (sweep.cpp).
#pragma once

#include <toml++/toml.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "sim_host/scene/scene.hpp"
#include "sim_host/studies/sweep.hpp"

namespace vines::host {

// A run's scene: the study's table with the run's keys set, and the Scene
// checked from it.
struct RunScene {
  toml::table table;
  Scene scene;
};

RunScene scene_with(const toml::table& base, const std::string& origin, const std::vector<KeyValue>& values);

// A cache key: the named tables of a run's scene as TOML text (toml++ keeps
// a table's keys sorted, so equal tables print alike), less the `drop` keys
// ("table.key"), after `prefix`.
std::string key_of(const std::string& prefix, const toml::table& doc, std::initializer_list<std::string_view> tables,
                   const std::vector<std::string_view>& drop = {});

}  // namespace vines::host
