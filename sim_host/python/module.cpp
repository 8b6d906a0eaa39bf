// The `vines._vines` extension (pybind11): the host library's scenes,
// records, runs and modal report for Python. The package around it
// (vines/__init__.py) gives the results their Python shape (attributes,
// numpy arrays); every check and message is the command line's own.
#include <algorithm>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <toml++/toml.h>

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/python/module.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/names.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/scene/table.hpp"

namespace py = pybind11;
using namespace vines;
using namespace vines::host;
using namespace vines::python;

namespace {

PyScene make_scene(toml::table table, const std::string& origin) {
  Scene s = scene_from_table(table, origin);
  return {std::move(table), origin, std::move(s)};
}

// Sets "section.key" (dotted, as in study specs) in a copy of the table.
PyScene with_overrides(const PyScene& s, const py::dict& overrides) {
  toml::table t = s.table;
  for (const auto& [k, v] : overrides) {
    const std::string key = py::str(k);
    toml::table* at = &t;
    std::size_t start = 0;
    for (std::size_t dot; (dot = key.find('.', start)) != std::string::npos; start = dot + 1) {
      const std::string part = key.substr(start, dot - start);
      toml::node* n = at->get(part);
      if (!n) n = &at->insert_or_assign(part, toml::table{}).first->second;
      if (!n->is_table()) throw SceneError(s.origin + ": " + key + ": " + part + " is not a table");
      at = n->as_table();
    }
    insert(*at, key.substr(start), v, s.origin, key);
  }
  return make_scene(std::move(t), s.origin);
}

// units= and format= of Record: the scene's [record] names.
hal::Units units_of(const std::string& u) {
  if (const auto v = named(kRecordUnits, u)) return *v;
  throw std::invalid_argument("units: '" + u + "' (g, m/s2 or cm/s2)");
}

hal::RecordFormat format_of(const std::string& f) {
  if (const auto v = named(kRecordFormats, f)) return *v;
  throw std::invalid_argument("format: '" + f + "' (auto, at2, time-accel or accel)");
}

// A ground-motion record: read from a file (then a run reads that file the
// way `vines run --record` does) or given as samples.
struct PyRecord {
  hal::Record record;
  bool from_file = false;
  RecordReading reading;
};

PyRecord load_record(const std::string& path, const std::string& format, const std::string& units, int column,
                     double dt) {
  PyRecord r;
  r.from_file = true;
  r.reading.format = format_of(format);
  r.reading.units = units_of(units);
  r.reading.column = column;
  r.reading.dt_s = dt;
  hal::RecordSpec spec;
  spec.path = path;
  spec.format = r.reading.format;
  spec.units = r.reading.units;
  spec.column = column;
  spec.dt_s = dt;
  r.record = hal::load_record(spec);
  return r;
}

PyRecord record_from_array(const py::array_t<double, py::array::c_style | py::array::forcecast>& acc, double dt,
                           double t0, const std::string& units, const std::string& name) {
  if (acc.ndim() != 1) throw std::invalid_argument(name + ": acc must be one-dimensional");
  PyRecord r;
  r.record.path = name;
  r.record.dt_s = dt;
  r.record.t0_s = t0;
  const double f = hal::unit_factor(units_of(units));
  const auto a = acc.unchecked<1>();
  r.record.accel_mps2.resize(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) r.record.accel_mps2[static_cast<std::size_t>(i)] = a(i) * f;
  hal::check_record(r.record);
  return r;
}

// A Snapshot's fields as Python names them (Series and Step, units in
// vines/__init__.py): one value each, then one per floor.
using ScalarOf = double (*)(const Snapshot&);
constexpr std::pair<const char*, ScalarOf> kScalarFields[] = {
    {"t", [](const Snapshot& s) { return s.t; }},
    {"ag", [](const Snapshot& s) { return s.ag; }},
    {"elastic_energy", [](const Snapshot& s) { return s.elastic_energy; }},
    {"particle_x", [](const Snapshot& s) { return s.particle_x; }},
    {"particle_v", [](const Snapshot& s) { return s.particle_v; }},
    {"wall_left", [](const Snapshot& s) { return s.wall_left; }},
    {"wall_right", [](const Snapshot& s) { return s.wall_right; }},
    {"contact_force", [](const Snapshot& s) { return s.contact_force; }},
    {"mode", [](const Snapshot& s) { return static_cast<double>(s.mode); }},
    {"tmd_x", [](const Snapshot& s) { return s.tmd_x; }},
    {"tmd_v", [](const Snapshot& s) { return s.tmd_v; }},
};
constexpr std::pair<const char*, FloorArray Snapshot::*> kFloorFields[] = {
    {"x", &Snapshot::x}, {"v", &Snapshot::v}, {"acc", &Snapshot::acc}, {"drift", &Snapshot::drift}};

// The series: one numpy array a field, over the rows (per floor: rows x stories).
py::dict series_dict(const std::vector<Snapshot>& rows, int stories) {
  const auto n = static_cast<py::ssize_t>(rows.size());
  py::dict d;
  for (const auto& [name, get] : kScalarFields) {
    py::array_t<double> out(n);
    auto o = out.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < n; ++i) o(i) = get(rows[static_cast<std::size_t>(i)]);
    d[name] = out;
  }
  for (const auto& [name, field] : kFloorFields) {
    py::array_t<double> out({n, static_cast<py::ssize_t>(stories)});
    auto o = out.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i)
      for (int j = 0; j < stories; ++j) o(i, j) = (rows[static_cast<std::size_t>(i)].*field)[static_cast<std::size_t>(j)];
    d[name] = out;
  }
  return d;
}

// The excitation of a record given as samples: its errors are RecordErrors
// (a record too short for one step at the sensor rate), as a file's are.
Excitation array_excitation(const PyScene& s, const PyRecord& record) {
  try {
    return excitation_from_record(s.scene, record.record);
  } catch (const hal::RecordError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw hal::RecordError(e.what());
  }
}

// Runs a scene (on its own record, or `record`), the GIL released while the
// loop runs; returns the summary (summary.json's text) and the series.
py::dict run(const PyScene& s, const PyRecord* record) {
  RunOptions opt;
  opt.keep_series = true;
  RunReport r;
  {
    Excitation ex;
    bool have_ex = false;
    if (record && !record->from_file) {
      ex = array_excitation(s, *record);
      have_ex = true;
    } else if (record) {
      opt.record_override = record->record.path;
      opt.record_reading = record->reading;
    }
    py::gil_scoped_release release;
    r = have_ex ? run_scene(s.scene, ex, opt) : run_scene(s.scene, opt);
  }
  py::dict out;
  out["summary"] = r.to_json().dump();
  out["series"] = series_dict(r.series, r.info.stories);
  if (r.bare) out["bare_series"] = series_dict(r.bare_series, r.info.stories);
  return out;
}

// The excitation a run of the scene steps through: its record (or
// `record`) scaled and resampled to the sensor rate [m/s^2].
py::array_t<double> samples(const PyScene& s, const PyRecord* record) {
  Excitation ex;
  if (record && !record->from_file) ex = array_excitation(s, *record);
  else if (record) ex = load_excitation(s.scene, record->record.path, record->reading);
  else ex = load_excitation(s.scene, "");
  return py::array_t<double>(static_cast<py::ssize_t>(ex.samples.size()), ex.samples.data());
}

py::array_t<double> floor_array(const FloorArray& a, int stories) {
  return py::array_t<double>(stories, a.data());
}

// One step's outputs (a Snapshot) as a dict.
py::dict step_dict(const Snapshot& s, int stories) {
  py::dict d;
  for (const auto& [name, get] : kScalarFields) d[name] = get(s);
  for (const auto& [name, field] : kFloorFields) d[name] = floor_array(s.*field, stories);
  d["mode"] = s.mode;  // a step's mode stays the integer code (vines::Mode)
  return d;
}

// The scene's device run stepped from Python, one sample at a time (a
// digital-twin prototype): the engine `vines run` uses, built once.
struct PyLoop {
  std::unique_ptr<Engine> eng;
  int stories = 0;
  bool ledger = false;  // loop.energy_ledger: totals has the balance's residual
  bool started = false;
  // run() stepping in another thread, the GIL released (set and read with
  // the GIL held): every call refused meanwhile, so that two threads never
  // step one building's state at once.
  bool busy = false;

  void require_free() const {
    if (busy)
      throw std::runtime_error(
          "vines.Loop: this loop is running samples in another thread; a Loop is one building's state, stepped "
          "by one thread at a time: give each thread its own (copy.deepcopy(loop))");
  }
  void require_started() const {
    require_free();
    if (!started) throw std::runtime_error("vines.Loop: reset(a0) first (the ground acceleration at t = 0)");
  }
};

// Marks a loop busy while run() steps it with the GIL released.
struct Busy {
  explicit Busy(PyLoop& l) : loop(l) { loop.busy = true; }
  ~Busy() { loop.busy = false; }
  Busy(const Busy&) = delete;
  Busy& operator=(const Busy&) = delete;
  PyLoop& loop;
};

PyLoop make_loop(const PyScene& s) {
  PyLoop l;
  refuse_damage(s.scene, "vines.Loop");
  l.eng = build_engine(s.scene.params, s.scene.scalar, s.scene.path);
  l.stories = l.eng->info().stories;
  l.ledger = s.scene.params.loop.energy_ledger;
  return l;
}

py::dict totals_dict(const RunTotals& t, int stories, bool ledger) {
  py::dict d;
  d["peak_top_displacement_m"] = t.peak_top;
  d["t_peak_top_s"] = t.t_peak_top;
  d["peak_displacement_m"] = floor_array(t.peak_x, stories);
  d["peak_drift_m"] = floor_array(t.peak_drift, stories);
  d["elastic_energy_integral"] = t.elastic_energy;
  d["contacts"] = t.count.contacts;
  d["max_overlap_m"] = t.max_overlap;
  d["steps"] = t.count.steps;
  d["bad_samples_held"] = t.count.bad_samples;
  d["divergences_rolled_back"] = t.count.divergences;
  // summary.json's: the ledger's largest |residual| over the largest energy in.
  d["energy_balance_residual"] = ledger ? py::object(py::float_(t.ledger.relative_residual())) : py::none();
  return d;
}

// The modal report of the scene's frame (with its device's floor), as JSON text.
std::string modal(const PyScene& s) {
  std::unique_ptr<Engine> eng = build_engine(s.scene.params, s.scene.scalar, s.scene.path);
  return modal_json(eng->info()).dump();
}

}  // namespace

PYBIND11_MODULE(_vines, m) {
  m.doc() = "vines core: scenes, records, runs (see the vines package)";
  py::register_exception<SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<hal::RecordError>(m, "RecordError", PyExc_ValueError);
  m.attr("__version__") = VINES_VERSION;

  py::class_<PyScene>(m, "Scene")
      .def_static("load", [](const std::string& path) { return make_scene(read_scene_table(path), path); },
                  py::arg("path"))
      .def_static("from_toml", [](const std::string& text, const std::string& origin) {
        return make_scene(parse_scene_table(text, origin), origin);
      }, py::arg("text"), py::arg("origin"))
      .def_static("from_dict", [](const py::dict& d, const std::string& origin) {
        return make_scene(to_table(d, origin, ""), origin);
      }, py::arg("d"), py::arg("origin"))
      .def("with_", &with_overrides, py::arg("overrides"))
      .def("to_toml", [](const PyScene& s) {
        std::ostringstream os;
        os << s.table;
        return os.str() + "\n";
      })
      .def("to_dict", [](const PyScene& s) { return to_dict(s.table); })
      .def_property_readonly("name", [](const PyScene& s) { return s.scene.name; })
      .def_property_readonly("device", [](const PyScene& s) { return device_name(s.scene.params.device.kind); })
      .def_property_readonly("origin", [](const PyScene& s) { return s.origin; })
      .def_property_readonly("stories", [](const PyScene& s) { return s.scene.params.frame.stories; })
      .def_property_readonly("sensor_rate_hz", [](const PyScene& s) { return s.scene.params.loop.sensor_rate_hz; })
      .def_property_readonly("output_rate_hz", [](const PyScene& s) { return s.scene.output.rate_hz; });

  py::class_<PyRecord>(m, "Record")
      .def_static("load", &load_record, py::arg("path"), py::arg("format"), py::arg("units"), py::arg("column"),
                  py::arg("dt"))
      .def_static("from_array", &record_from_array, py::arg("acc"), py::arg("dt"), py::arg("t0"), py::arg("units"),
                  py::arg("name"))
      .def_property_readonly("path", [](const PyRecord& r) { return r.record.path; })
      .def_property_readonly("dt", [](const PyRecord& r) { return r.record.dt_s; })
      .def_property_readonly("t0", [](const PyRecord& r) { return r.record.t0_s; })
      .def_property_readonly("acc", [](const PyRecord& r) {
        return py::array_t<double>(static_cast<py::ssize_t>(r.record.accel_mps2.size()), r.record.accel_mps2.data());
      })
      .def_property_readonly("pga", [](const PyRecord& r) { return r.record.pga_mps2(); })
      .def("__len__", [](const PyRecord& r) { return r.record.accel_mps2.size(); });

  py::class_<PyLoop>(m, "Loop")
      .def(py::init(&make_loop), py::arg("scene"))
      .def("reset", [](PyLoop& l, double a0) {
        l.require_free();
        l.eng->init(a0);
        l.started = true;
        return step_dict(l.eng->snapshot(), l.stories);
      }, py::arg("a0"))
      .def("step", [](PyLoop& l, double a) {
        l.require_started();
        l.eng->step(a);
        return step_dict(l.eng->snapshot(), l.stories);
      }, py::arg("a"))
      .def("run", [](PyLoop& l, const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
        l.require_started();
        if (a.ndim() != 1) throw std::invalid_argument("vines.Loop.run: the samples must be one-dimensional");
        // In chunks, Ctrl-C heard between them (KeyboardInterrupt: the loop
        // then at the end of the last chunk run, its state whole).
        constexpr std::size_t kChunk = std::size_t{1} << 16;
        const std::size_t n = static_cast<std::size_t>(a.shape(0));
        const Busy busy(l);
        for (std::size_t at = 0; at < n; at += kChunk) {
          {
            py::gil_scoped_release release;
            l.eng->run(a.data() + at, std::min(kChunk, n - at));
          }
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        }
        return step_dict(l.eng->snapshot(), l.stories);
      }, py::arg("samples"))
      .def_property_readonly("started", [](const PyLoop& l) { return l.started; })
      .def("now", [](const PyLoop& l) {
        l.require_started();
        return step_dict(l.eng->snapshot(), l.stories);
      })
      .def("state", [](const PyLoop& l) {
        l.require_started();
        const std::vector<std::uint8_t> b = l.eng->state();
        return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
      })
      .def("load_state", [](PyLoop& l, const py::bytes& b) {
        l.require_free();
        const std::string data = b;
        const std::string why = l.eng->load_state(reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
        if (!why.empty()) throw std::invalid_argument("vines.Loop.set_state: " + why);
        l.started = true;
      }, py::arg("state"))
      .def("set_physical", [](PyLoop& l, const py::dict& d) {
        l.require_started();
        PhysicalState p;
        for (const auto& [k, v] : d) {
          const std::string name = py::str(k);
          if (name == "x" || name == "v") {
            const auto a = v.cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
            if (a.ndim() != 1 || a.shape(0) != l.stories)
              throw std::invalid_argument("vines.Loop.set_state: " + name + ": one value a floor");
            FloorArray& to = name == "x" ? p.x : p.v;
            for (int j = 0; j < l.stories; ++j) to[static_cast<std::size_t>(j)] = a.at(j);
          } else if (name == "particle_x") p.particle_x = v.cast<double>();
          else if (name == "particle_v") p.particle_v = v.cast<double>();
          else if (name == "tmd_x") p.tmd_x = v.cast<double>();
          else if (name == "tmd_v") p.tmd_v = v.cast<double>();
          else throw std::invalid_argument("vines.Loop.set_state: no field " + name);
        }
        const std::string why = l.eng->set_physical(p);
        if (!why.empty()) throw std::invalid_argument("vines.Loop.set_state: " + why);
      }, py::arg("fields"))
      .def_property_readonly("totals", [](const PyLoop& l) {
        l.require_started();
        return totals_dict(l.eng->totals(), l.stories, l.ledger);
      });

  m.def("find_record", [](const std::string& path) {
    try {
      return resolve_record_path(path, "vines.Record.load");
    } catch (const SceneError& e) {
      throw hal::RecordError(e.what());
    }
  }, py::arg("path"));
  m.def("run", &run, py::arg("scene"), py::arg("record") = nullptr);
  m.def("samples", &samples, py::arg("scene"), py::arg("record") = nullptr);
  m.def("modal", &modal, py::arg("scene"));
  m.def("sweep", &sweep, py::arg("scene"), py::arg("grid"), py::arg("set"), py::arg("cases"), py::arg("group_by"),
        py::arg("threads"), py::arg("large"));
}
