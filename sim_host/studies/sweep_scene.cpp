#include "sim_host/studies/sweep_scene.hpp"

#include <cmath>
#include <cstdint>
#include <sstream>

#include "sim_host/scene/table.hpp"

namespace vines::host {
namespace {

// Sets (or removes) a dotted key "table.key" in a scene's table.
void set_key(toml::table& root, const KeyValue& v) {
  const auto dot = v.key.find('.');
  const std::string table = v.key.substr(0, dot), key = v.key.substr(dot + 1);
  toml::table* t = root[table].as_table();
  if (!t) t = root.insert_or_assign(table, toml::table{}).first->second.as_table();
  if (v.record_file) {  // read as vines run --record reads it: its own format, units, column, time step
    for (const char* k : {"format", "units", "dt_s", "column"}) t->erase(k);
    t->insert_or_assign(key, v.text);
  } else if (v.text == "unset") t->erase(key);
  else if (v.text == "true" || v.text == "false") t->insert_or_assign(key, v.text == "true");
  else if (!v.text.empty()) t->insert_or_assign(key, v.text);
  else if (v.integral) t->insert_or_assign(key, static_cast<int64_t>(std::llround(v.number)));
  else t->insert_or_assign(key, v.number);
}

}  // namespace

RunScene scene_with(const toml::table& base, const std::string& origin, const std::vector<KeyValue>& values) {
  RunScene r{base, {}};
  for (const KeyValue& v : values) set_key(r.table, v);
  r.scene = scene_from_table(r.table, origin);
  return r;
}

std::string key_of(const std::string& prefix, const toml::table& doc, std::initializer_list<std::string_view> tables,
                   const std::vector<std::string_view>& drop) {
  toml::table part;
  for (std::string_view t : tables)
    if (const toml::node* n = doc.get(t)) part.insert(t, *n);
  for (std::string_view d : drop) {
    const std::size_t dot = d.find('.');
    if (toml::table* t = part[d.substr(0, dot)].as_table()) t->erase(d.substr(dot + 1));
  }
  std::ostringstream k;
  k << prefix << '|' << part;
  return k.str();
}

}  // namespace vines::host
