// Python values as TOML nodes, checked as a scene file's would be.
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>

#include "sim_host/python/module.hpp"

namespace vines::python {
namespace {

[[noreturn]] void bad_type(const std::string& where, const py::handle v) {
  throw py::type_error(where + ": a value of type " + std::string(py::str(v.get_type().attr("__name__"))) +
                       " (bool, int, float, str, list or dict)");
}

}  // namespace

void insert(toml::table& t, const std::string& name, const py::handle v, const std::string& origin,
            const std::string& key) {
  if (py::isinstance<py::bool_>(v)) t.insert_or_assign(name, v.cast<bool>());
  else if (py::isinstance<py::int_>(v)) t.insert_or_assign(name, v.cast<std::int64_t>());
  else if (py::isinstance<py::float_>(v)) t.insert_or_assign(name, v.cast<double>());
  else if (py::isinstance<py::str>(v)) t.insert_or_assign(name, v.cast<std::string>());
  else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) t.insert_or_assign(name, to_array(v, origin, key));
  else if (py::isinstance<py::dict>(v)) t.insert_or_assign(name, to_table(v.cast<py::dict>(), origin, key));
  else bad_type(origin + ": " + key, v);
}

toml::array to_array(const py::handle l, const std::string& origin, const std::string& key) {
  toml::array out;
  for (const py::handle item : l) {
    if (py::isinstance<py::bool_>(item)) out.push_back(item.cast<bool>());
    else if (py::isinstance<py::int_>(item)) out.push_back(item.cast<std::int64_t>());
    else if (py::isinstance<py::float_>(item)) out.push_back(item.cast<double>());
    else if (py::isinstance<py::str>(item)) out.push_back(item.cast<std::string>());
    else if (py::isinstance<py::list>(item) || py::isinstance<py::tuple>(item)) out.push_back(to_array(item, origin, key));
    else if (py::isinstance<py::dict>(item)) out.push_back(to_table(item.cast<py::dict>(), origin, key));
    else bad_type(origin + ": " + key, item);
  }
  return out;
}

toml::table to_table(const py::dict& d, const std::string& origin, const std::string& prefix) {
  toml::table out;
  for (const auto& [k, v] : d) {
    const std::string name = py::str(k);
    insert(out, name, v, origin, prefix.empty() ? name : prefix + "." + name);
  }
  return out;
}

namespace {

py::object to_python(const toml::node& n) {
  if (const auto* t = n.as_table()) return to_dict(*t);
  if (const auto* a = n.as_array()) {
    py::list out;
    for (const toml::node& item : *a) out.append(to_python(item));
    return std::move(out);
  }
  if (const auto v = n.value_exact<bool>()) return py::bool_(*v);
  if (const auto v = n.value_exact<std::int64_t>()) return py::int_(*v);
  if (const auto v = n.value_exact<double>()) return py::float_(*v);
  if (const auto v = n.value_exact<std::string>()) return py::str(*v);
  // Dates and times: a scene has none; their TOML text if one appears.
  std::ostringstream os;
  n.visit([&](const auto& x) { os << x; });
  return py::str(os.str());
}

}  // namespace

py::dict to_dict(const toml::table& t) {
  py::dict out;
  for (const auto& [k, v] : t) out[py::str(std::string(k.str()))] = to_python(v);
  return out;
}

}  // namespace vines::python
