// What the extension's files share (module.cpp the bindings, values.cpp
// Python values as TOML, sweep.cpp the study).
#pragma once

#include <pybind11/pybind11.h>

#include <toml++/toml.h>

#include <string>

#include "sim_host/scene/scene.hpp"

namespace vines::python {

namespace py = pybind11;

// A scene: its TOML table (what with_() edits and to_toml() writes) and the
// checked Scene made from it. origin names it in messages and is the path
// relative record paths are resolved against.
struct PyScene {
  toml::table table;
  std::string origin;
  host::Scene scene;
};

// Python values as TOML nodes: bool, int, float, str, list (or tuple), dict
// (nested; the package has made numpy values these). `where` names the
// value in messages: "origin: section.key"; another type is a TypeError.
toml::table to_table(const py::dict& d, const std::string& origin, const std::string& prefix);
toml::array to_array(const py::handle l, const std::string& origin, const std::string& key);
// A TOML table as nested Python dicts, lists and values (Scene.to_dict).
py::dict to_dict(const toml::table& t);
// Sets t[name] to the value v; key names it in messages.
void insert(toml::table& t, const std::string& name, const py::handle v, const std::string& origin,
            const std::string& key);

// A study of the scene as `vines sweep` runs one: grid (a key's list of
// values, or {from, to, step | count, scale}, as in [study.grid]), set (fixed
// keys), cases (a list of dicts of paired keys), on `threads` threads (0: all
// cores; at most kMaxThreads) with the GIL released; a plan above kLargePlan
// runs only with `large`. Returns each run's keys and results, in the order
// of the spec's plan (results.csv's rows).
py::dict sweep(const PyScene& s, const py::dict& grid, const py::dict& set, const py::list& cases,
               const std::string& group_by, int threads, bool large);

}  // namespace vines::python
