// The reading side of scene files (scene.cpp): one top-level TOML table of a
// scene and its typed, checked reads, with messages that name the file, the
// line and the key. Internal to scene.cpp and damage.cpp.
#pragma once

#include <toml++/toml.h>

#include <algorithm>
#include <climits>
#include <initializer_list>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "sim_host/scene/scene.hpp"

namespace vines::host::scene_detail {

// Throws "origin:LINE: key: what"; the line and the key are left out when
// unknown / empty.
[[noreturn]] inline void fail(const std::string& origin, const toml::source_region* where,
                       const std::string& key, const std::string& what) {
  std::string msg = origin;
  if (where != nullptr && where->begin.line > 0) msg += ":" + std::to_string(where->begin.line);
  msg += ": ";
  if (!key.empty()) msg += key + ": ";
  throw SceneError(msg + what);
}

// "a, b, c" for messages.
inline std::string join(std::initializer_list<std::string_view> names) {
  std::string out;
  for (std::string_view n : names) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

// A name -> value table for string-valued choices.
template <class E>
using Choices = std::vector<std::pair<std::string_view, E>>;

// One top-level table of the scene file. The constructor refuses keys not in
// `known`. Each read() leaves *out alone and returns false when the key is
// absent, converts and returns true when it is present, and throws when it is
// present with the wrong type.
class Section {
 public:
  Section(const std::string& origin, const toml::table& root, std::string name,
          std::initializer_list<std::string_view> known)
      : origin_(origin), name_(std::move(name)) {
    const toml::node* n = root.get(name_);
    if (n == nullptr) return;
    table_ = n->as_table();
    if (table_ == nullptr) fail(origin_, &n->source(), name_, "must be a table");
    for (auto&& kv : *table_)
      if (std::find(known.begin(), known.end(), kv.first.str()) == known.end())
        fail(origin_, &kv.first.source(), key(kv.first.str()),
             "unknown key (known: " + join(known) + ")");
  }

  bool present() const { return table_ != nullptr; }
  bool has(std::string_view k) const { return node(k) != nullptr; }
  std::string key(std::string_view k) const { return name_ + "." + std::string(k); }

  // Throws at the key's line (or the line of its element `index`).
  [[noreturn]] void fail_at(std::string_view k, const std::string& what, int index = -1) const {
    const toml::node* n = node(k);
    std::string name = key(k);
    if (index >= 0) {
      name += "[" + std::to_string(index) + "]";
      if (n != nullptr && n->is_array()) n = n->as_array()->get(static_cast<std::size_t>(index));
    }
    fail(origin_, n != nullptr ? &n->source() : nullptr, name, what);
  }

  bool read(std::string_view k, double* out) const {
    const toml::node* n = node(k);
    if (n == nullptr) return false;
    if (!to_double(*n, out)) fail_at(k, "must be a number");
    return true;
  }

  bool read(std::string_view k, int* out) const {
    const toml::node* n = node(k);
    if (n == nullptr) return false;
    if (!to_int(*n, out)) fail_at(k, "must be an integer");
    return true;
  }

  bool read(std::string_view k, bool* out) const {
    const toml::node* n = node(k);
    if (n == nullptr) return false;
    if (!n->is_boolean()) fail_at(k, "must be true or false");
    *out = n->as_boolean()->get();
    return true;
  }

  bool read(std::string_view k, std::string* out) const {
    const toml::node* n = node(k);
    if (n == nullptr) return false;
    if (!n->is_string()) fail_at(k, "must be a string");
    *out = n->as_string()->get();
    return true;
  }

  // Arrays of numbers (T = double) or of integers (T = int).
  template <class T>
  bool read(std::string_view k, std::vector<T>* out) const {
    const toml::node* n = node(k);
    if (n == nullptr) return false;
    const toml::array* a = n->as_array();
    if (a == nullptr) fail_at(k, "must be an array");
    out->assign(a->size(), T{});
    for (std::size_t i = 0; i < a->size(); ++i) {
      if constexpr (std::is_same_v<T, int>) {
        if (!to_int((*a)[i], &(*out)[i])) fail_at(k, "must be an integer", static_cast<int>(i));
      } else {
        if (!to_double((*a)[i], &(*out)[i])) fail_at(k, "must be a number", static_cast<int>(i));
      }
    }
    return true;
  }

  // A fixed-length array (the Rayleigh pairs).
  template <class T, std::size_t L>
  bool read_fixed(std::string_view k, T (&out)[L]) const {
    std::vector<T> v;
    if (!read(k, &v)) return false;
    if (v.size() != L) fail_at(k, "must have " + std::to_string(L) + " elements");
    std::copy(v.begin(), v.end(), out);
    return true;
  }

  // A string naming one of `choices`.
  template <class E>
  bool choose(std::string_view k, Choices<E> choices, E* out) const {
    std::string s;
    const toml::node* n = node(k);
    if (n != nullptr && !n->is_string()) fail_at(k, "must be a string: " + names(choices));
    if (!read(k, &s)) return false;
    for (const auto& [name, value] : choices)
      if (s == name) {
        *out = value;
        return true;
      }
    fail_at(k, "must be one of " + names(choices) + " (got \"" + s + "\")");
  }

  // A "0 means not given" key: when written, it must not be 0.
  bool read_nonzero(std::string_view k, double* out) const {
    if (!read(k, out)) return false;
    if (*out == 0.0) fail_at(k, "must be > 0 (leave the key out for the default)");
    return true;
  }

  // Two keys that set the same thing.
  void exclusive(std::string_view a, std::string_view b) const {
    if (has(a) && has(b)) fail_at(b, "conflicts with " + key(a) + " (give one of them)");
  }

 private:
  const toml::node* node(std::string_view k) const {
    return table_ != nullptr ? table_->get(k) : nullptr;
  }

  static bool to_double(const toml::node& n, double* out) {
    if (const auto* f = n.as_floating_point()) {
      *out = f->get();
      return true;
    }
    if (const auto* i = n.as_integer()) {
      *out = static_cast<double>(i->get());
      return true;
    }
    return false;
  }

  static bool to_int(const toml::node& n, int* out) {
    const auto* i = n.as_integer();
    if (i == nullptr || i->get() < INT_MIN || i->get() > INT_MAX) return false;
    *out = static_cast<int>(i->get());
    return true;
  }

  template <class E>
  static std::string names(Choices<E> choices) {
    std::string out;
    for (const auto& c : choices)
      out += (out.empty() ? "\"" : ", \"") + std::string(c.first) + "\"";
    return out;
  }

  const std::string& origin_;
  std::string name_;
  const toml::table* table_ = nullptr;
};

// [damage] (damage.cpp): time_s and one factor in (0, 1] per story.
void read_damage(const Section& s, int stories, DamageSpec* d);

}  // namespace vines::host::scene_detail
