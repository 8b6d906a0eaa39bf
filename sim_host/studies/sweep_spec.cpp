// `vines sweep` specs: the [[study]] tables of a spec file, checked (format
// at the top of sweep.hpp); the runs they make are sweep_plan.cpp's.
#include <fnmatch.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/studies/sweep.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

// ---- spec parsing ----

// A grid value list: explicit values, a range table, or a list mixing both.
struct Scaled {
  std::vector<KeyValue> values;
  std::string scale;  // "", "gap" or "vmax"
};

KeyValue value_of(const std::string& where, const std::string& key, const toml::node& n) {
  KeyValue v;
  v.key = key;
  if (auto i = n.as_integer()) {
    v.number = static_cast<double>(i->get());
    v.integral = true;
  } else if (auto f = n.as_floating_point()) {
    v.number = f->get();
  } else if (auto s = n.as_string()) {
    v.text = s->get();
  } else if (auto b = n.as_boolean()) {
    v.text = b->get() ? "true" : "false";
  } else {
    fail(where, key + ": values must be numbers, strings or booleans");
  }
  return v;
}

// Values of a range table {from, to, step | count, scale}.
std::vector<double> range_values(const std::string& where, const std::string& key,
                                 const toml::table& t, std::string* scale, bool* integral) {
  for (auto&& kv : t)
    if (kv.first != "from" && kv.first != "to" && kv.first != "step" && kv.first != "count" &&
        kv.first != "scale")
      fail(where, key + ": unknown range key '" + std::string(kv.first.str()) +
                      "' (known: from, to, step, count, scale)");
  const auto from = t["from"].value<double>(), to = t["to"].value<double>();
  if (!from || !to) fail(where, key + ": a range needs numbers 'from' and 'to'");
  if (auto s = t["scale"].value<std::string>()) {
    if (*s != "gap" && *s != "vmax") fail(where, key + ": scale must be \"gap\" or \"vmax\"");
    *scale = *s;
  }
  *integral = t["from"].is_integer() && t["to"].is_integer() && t["step"].is_integer();
  std::vector<double> out;
  if (auto step = t["step"].value<double>()) {
    if (!(*step > 0)) fail(where, key + ": step must be > 0");
    const double n = std::floor((*to - *from) / *step + 1e-9);
    if (n < 0 || n > 1e6) fail(where, key + ": empty or huge range");
    for (int i = 0; i <= static_cast<int>(n); ++i) {
      const double x = *from + i * *step;
      out.push_back(std::round(x * 1e12) / 1e12);  // 1.05 + 3 * 0.05 prints as 1.2
    }
  } else if (auto count = t["count"].value<int64_t>()) {
    if (*count < 1 || *count > 1000000) fail(where, key + ": count must be in [1, 1e6]");
    for (int64_t i = 0; i < *count; ++i)
      out.push_back(*count == 1 ? *from : *from + (*to - *from) * static_cast<double>(i) / (*count - 1));
  } else {
    fail(where, key + ": a range needs 'step' or 'count'");
  }
  return out;
}

// The most values a grid key's list or range makes (before any is built; a
// union may make fewer), saturating; a malformed range counts 1 (refused later).
std::uint64_t axis_count(const toml::node& n) {
  auto range = [](const toml::table& t) -> std::uint64_t {
    const auto from = t["from"].value<double>(), to = t["to"].value<double>(), step = t["step"].value<double>();
    const auto count = t["count"].value<int64_t>();
    if (count && *count > 0) return static_cast<std::uint64_t>(*count);
    if (!from || !to || !step || !(*step > 0)) return 1;
    const double k = std::floor((*to - *from) / *step + 1e-9) + 1;
    return k < 1 ? 1 : k > 1e18 ? std::numeric_limits<std::uint64_t>::max() : static_cast<std::uint64_t>(k);
  };
  if (const toml::table* t = n.as_table()) return range(*t);
  std::uint64_t k = 0;
  if (const toml::array* a = n.as_array())
    for (auto&& e : *a) k = std::min<std::uint64_t>(k + (e.as_table() ? range(*e.as_table()) : 1), 1ULL << 62);
  return k;
}

Scaled grid_axis(const std::string& where, const std::string& key, const toml::node& n) {
  Scaled ax;
  std::vector<double> numbers, listed;  // every value; those listed one by one
  bool all_integral = true;
  auto add_range = [&](const toml::table& t) {
    std::string scale;
    bool integral = false;
    for (double x : range_values(where, key, t, &scale, &integral)) numbers.push_back(x);
    all_integral &= integral;
    if (!ax.scale.empty() && ax.scale != scale) fail(where, key + ": ranges with different scales");
    ax.scale = scale;
  };
  if (auto t = n.as_table()) {
    add_range(*t);
  } else if (auto a = n.as_array()) {
    for (auto&& e : *a) {
      if (auto tt = e.as_table()) {
        add_range(*tt);
      } else {
        KeyValue v = value_of(where, key, e);
        if (!v.text.empty()) {
          for (const KeyValue& w : ax.values)
            if (w.text == v.text) fail(where, key + ": '" + v.text + "' is listed twice (one run): drop one");
          ax.values.push_back(v);
        } else {
          numbers.push_back(v.number), listed.push_back(v.number);
          all_integral &= v.integral;
        }
      }
    }
  } else {
    fail(where, key + ": a grid key takes a list of values or a range table");
  }
  // Union of the numbers, sorted, without duplicates: equal values of ranges
  // that share an end are one run; a value listed twice is refused, as are
  // distinct values within 1e-12 of each other relatively (their columns in
  // results.csv would read the same).
  std::sort(listed.begin(), listed.end());
  for (std::size_t i = 1; i < listed.size(); ++i)
    if (listed[i] == listed[i - 1]) {
      char msg[160];
      std::snprintf(msg, sizeof msg, ": %.17g is listed twice (one run): drop one", listed[i]);
      fail(where, key + msg);
    }
  std::sort(numbers.begin(), numbers.end());
  numbers.erase(std::unique(numbers.begin(), numbers.end()), numbers.end());
  for (std::size_t i = 1; i < numbers.size(); ++i)
    if (std::fabs(numbers[i] - numbers[i - 1]) <= 1e-12 * std::max(std::fabs(numbers[i]), std::fabs(numbers[i - 1]))) {
      char msg[160];
      std::snprintf(msg, sizeof msg, ": values %.17g and %.17g differ by less than 1e-12 of their size (one run): drop one",
                    numbers[i - 1], numbers[i]);
      fail(where, key + msg);
    }
  for (double x : numbers) {
    KeyValue v;
    v.key = key;
    v.number = x;
    v.integral = all_integral && ax.scale.empty();
    ax.values.push_back(v);
  }
  if (ax.values.empty()) fail(where, key + ": no values");
  return ax;
}

// The files of a record folder { folder = "DIR", glob = "PATTERN" } (DIR
// relative to the spec's folder), sorted by name, each checked readable as a
// record: an unreadable file, a missing folder or no match is refused.
std::vector<KeyValue> folder_axis(const std::string& where, const std::string& key, const toml::table& t,
                                  const fs::path& spec_dir) {
  for (auto&& kv : t)
    if (kv.first != "folder" && kv.first != "glob")
      fail(where, key + ": unknown record folder key '" + std::string(kv.first.str()) + "' (known: folder, glob)");
  if (key != "record.path") fail(where, key + ": a folder gives values of record.path only");
  const auto folder = t["folder"].value<std::string>();
  const std::string glob = t["glob"].value_or(std::string("*"));
  if (!folder || folder->empty()) fail(where, key + ": folder must be a folder name");
  const fs::path dir = fs::absolute(spec_dir / *folder).lexically_normal();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    fail(where, key + ": folder '" + *folder + "' (" + dir.string() + "): not a folder");
  std::vector<std::string> files;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (fnmatch(glob.c_str(), name.c_str(), FNM_PERIOD) == 0 && e.is_regular_file(ec)) files.push_back(e.path());
  }
  if (ec) fail(where, key + ": folder '" + dir.string() + "': cannot list: " + ec.message());
  if (files.empty()) fail(where, key + ": no file in folder '" + dir.string() + "' matches glob '" + glob + "'");
  std::sort(files.begin(), files.end());
  std::vector<KeyValue> out;
  for (const std::string& f : files) {
    // Read now, as a run will (vines run --record): a file that cannot be read is refused, not skipped.
    hal::RecordSpec rs;
    rs.path = f;
    std::string why;
    try {
      if (hal::detect_record_format(f) == hal::RecordFormat::kAccel) why = "one column of values and no time step";
      else hal::load_record(rs);
    } catch (const std::exception& e) {
      why = e.what();
    }
    if (!why.empty())
      fail(where, key + ": " + f + ": cannot be read as a record file: " + why +
                      " (choose a glob that leaves it out)");
    KeyValue v;
    v.key = key;
    v.text = f;
    v.record_file = true;
    out.push_back(v);
  }
  return out;
}

void check_keys(const std::string& where, const toml::table& t,
                std::initializer_list<std::string_view> known) {
  for (auto&& kv : t)
    if (std::find(known.begin(), known.end(), kv.first.str()) == known.end())
      fail(where, "unknown key '" + std::string(kv.first.str()) + "'");
}

std::vector<KeyValue> key_values(const std::string& where, const toml::table& t) {
  std::vector<KeyValue> out;
  for (auto&& kv : t) out.push_back(value_of(where, std::string(kv.first.str()), kv.second));
  return out;
}

}  // namespace

std::string KeyValue::column() const { return scaled() ? key + "/" + text.substr(6) : key; }

std::string KeyValue::label() const {
  if (!text.empty() && !scaled()) return text;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", number);
  return buf;
}

// ---- spec file ----
SweepSpec load_sweep(const std::string& path) {
  std::string text;
  try {
    text = hal::read_input_file(path, kMaxSceneBytes);  // a regular file of bounded size
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(e.what()) + " (a study spec)");
  }
  SweepSpec spec = parse_sweep(text, path);
  // Every study's scene must load.
  for (const StudySpec& st : spec.studies) load_scene(st.scene_path);
  return spec;
}

SweepSpec parse_sweep(const std::string& text, const std::string& path) {
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    fail(path + ":" + std::to_string(e.source().begin.line), "TOML syntax error: " + std::string(e.description()));
  }
  check_keys(path, root, {"study"});
  const toml::array* studies = root["study"].as_array();
  if (!studies || studies->empty()) fail(path, "needs at least one [[study]]");
  SweepSpec spec;
  spec.path = path;
  double planned = 0;  // runs of the studies so far
  std::map<std::string, std::string> names;  // study name -> where it was given
  for (auto&& node : *studies) {
    const toml::table* t = node.as_table();
    if (!t) fail(path, "study: must be a table");
    const std::string where = path + ":" + std::to_string(t->source().begin.line);
    check_keys(where, *t, {"name", "scene", "group_by", "optimize", "set", "cases", "grid"});
    StudySpec st;
    st.name = t->at_path("name").value_or(std::string("study") + std::to_string(spec.studies.size() + 1));
    if (const auto [it, fresh] = names.emplace(st.name, where); !fresh)
      fail(where, "study '" + st.name + "': a second study of that name (the first at " + it->second + ")");
    const auto scene = t->at_path("scene").value<std::string>();
    if (!scene) fail(where, "study '" + st.name + "': needs scene = \"file.toml\"");
    st.scene_path = (fs::path(path).parent_path() / *scene).lexically_normal().string();
    st.group_by = t->at_path("group_by").value_or(std::string());
    st.optimize = t->at_path("optimize").value_or(std::string());
    if (!st.optimize.empty() && st.optimize != "x_r" && st.optimize != "E_r")
      fail(where, "optimize must be \"x_r\" or \"E_r\"");
    if (auto s = t->at_path("set").as_table()) st.set = key_values(where, *s);
    if (auto c = t->at_path("cases").as_array())
      for (auto&& e : *c) {
        if (!e.as_table()) fail(where, "cases: each case is a table of key = value");
        st.cases.push_back(key_values(where, *e.as_table()));
      }
    // The size of the plan so far, from the counts alone: a grid beyond any
    // machine (a 1e5 x 1e5 grid) is refused before a value is built.
    if (auto g = t->at_path("grid").as_table()) {
      double runs = static_cast<double>(std::max<std::size_t>(1, st.cases.size()));
      for (auto&& kv : *g) runs *= static_cast<double>(axis_count(kv.second));
      planned += runs;
      if (planned > static_cast<double>(kMaxPlanRuns)) {
        char size[96];
        std::snprintf(size, sizeof size, "the plan has %.0f runs, more than any sweep can hold (%llu)", planned,
                      static_cast<unsigned long long>(kMaxPlanRuns));
        fail(where, std::string(size) + ": split the grid");
      }
    }
    if (auto g = t->at_path("grid").as_table())
      for (auto&& kv : *g) {
        const std::string key(kv.first.str());
        if (const toml::table* f = kv.second.as_table(); f && f->contains("folder")) {
          st.grid_axes.push_back(folder_axis(where, key, *f, fs::path(path).parent_path()));
          continue;
        }
        Scaled ax = grid_axis(where, key, kv.second);
        if (!ax.scale.empty())
          for (KeyValue& v : ax.values) v.text = "scale:" + ax.scale;
        st.grid_axes.push_back(ax.values);
      }
    // Every key this study sets (fixed, per case, per grid axis) is a scene
    // key, set in one place only (a key in both [study.set] and the grid
    // would have one value silently win).
    std::map<std::string, std::string> placed;  // key -> where the study sets it
    auto check_key = [&](const KeyValue& v, const std::string& in) {
      if (v.key.find('.') == std::string::npos) fail(where, v.key + ": keys are table.key");
      if (!is_scene_key(v.key)) fail(where, v.key + ": not a scene key (data/scenes/README.md lists them)");
      const auto [it, fresh] = placed.emplace(v.key, in);
      if (!fresh && it->second != in) fail(where, v.key + ": set in both " + it->second + " and " + in);
    };
    for (const KeyValue& v : st.set) check_key(v, "[study.set]");
    for (const auto& c : st.cases)
      for (const KeyValue& v : c) check_key(v, "[[study.cases]]");
    for (const auto& ax : st.grid_axes) check_key(ax.front(), "[study.grid]");
    if (!st.group_by.empty()) {
      bool found = false;
      for (const auto& ax : st.grid_axes) found |= ax.front().key == st.group_by;
      if (!found) fail(where, "group_by '" + st.group_by + "' is not a grid key");
    }
    spec.studies.push_back(st);
  }
  return spec;
}

}  // namespace vines::host
