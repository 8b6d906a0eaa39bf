// A study of a Python scene, as `vines sweep` runs one.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <future>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "sim_host/python/module.hpp"
#include "sim_host/studies/sweep.hpp"

namespace vines::python {

using namespace vines::host;

py::dict sweep(const PyScene& s, const py::dict& grid, const py::dict& set, const py::list& cases,
               const std::string& group_by, int threads, bool large) {
  const std::string origin = s.origin + " (sweep)";
  if (threads < 0 || threads > kMaxThreads)
    throw std::invalid_argument("vines.sweep: threads: " + std::to_string(threads) + "; must be 0 (every core) to " +
                                std::to_string(kMaxThreads));
  toml::table study;
  study.insert("name", "python");
  study.insert("scene", "scene.toml");  // the study's scene is s, set below
  if (!group_by.empty()) study.insert("group_by", group_by);
  if (!grid.empty()) study.insert("grid", to_table(grid, origin, "grid"));
  if (!set.empty()) study.insert("set", to_table(set, origin, "set"));
  if (!cases.empty()) study.insert("cases", to_array(cases, origin, "cases"));
  toml::array studies;
  studies.push_back(std::move(study));
  toml::table root;
  root.insert("study", std::move(studies));
  std::ostringstream text;
  text << root;
  // The spec's errors (a key that is not a scene key, a bad range, a key
  // set twice, group_by) are the scene's: SceneError, raised before any run.
  SweepSpec spec;
  std::vector<RunPlan> plan;
  try {
    spec = parse_sweep(text.str(), origin);
    spec.studies[0].scene_path = s.origin;
    std::ostringstream scene;
    scene << s.table;
    spec.studies[0].scene_toml = scene.str();
    // As `vines sweep` does: a plan above kLargePlan runs needs large=True
    // (its plan alone takes gigabytes before any run), and one that would
    // take more than half the machine's memory is refused whatever.
    const std::uint64_t n = plan_size(spec);
    if (n > kLargePlan) {
      const double memory = plan_memory_bytes(spec, n);
      std::ostringstream why;
      why << origin << ": the plan has " << n << " runs (more than " << kLargePlan << ") and needs about "
          << static_cast<double>(static_cast<long long>(memory / 1e8)) / 10 << " GB of memory";
      if (memory > machine_memory_bytes() / 2) throw std::invalid_argument(why.str() + ", more than half of this machine's: split the grid");
      if (!large) throw std::invalid_argument(why.str() + ": pass large=True to run it");
    }
    plan = plan_runs(spec);
  } catch (const SceneError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  // The runs on their own thread, the GIL released; Python's signals are
  // checked every 0.1 s meanwhile: Ctrl-C stops the sweep (the runs under
  // way are dropped within a second) and raises KeyboardInterrupt.
  std::atomic<bool> stop{false};
  auto job = std::async(std::launch::async, [&] { return execute(spec, plan, threads, 0, 1, &stop, false); });
  for (;;) {
    std::future_status st;
    {
      py::gil_scoped_release release;
      st = job.wait_for(std::chrono::milliseconds(100));
    }
    if (st == std::future_status::ready) break;
    if (PyErr_CheckSignals() != 0) {
      stop = true;
      {
        py::gil_scoped_release release;
        job.wait();
      }
      throw py::error_already_set();
    }
  }
  const std::vector<RunResult> results = job.get();
  // Columns: the plan's keys (results.csv's names), then the results.
  py::dict out;
  py::list keys;
  std::vector<py::list> values;
  if (!plan.empty())
    for (const KeyValue& v : plan[0].values) {
      keys.append(v.column());
      values.emplace_back();
    }
  const auto n = static_cast<py::ssize_t>(results.size());
  py::array_t<double> x_r(n), e_r(n), peak(n), ee(n);
  py::array_t<long long> contacts(n);
  py::list status, reasons, errors;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const RunResult& r = results[i];
    for (std::size_t k = 0; k < values.size() && k < plan[i].values.size(); ++k) {
      const KeyValue& v = plan[i].values[k];
      if (v.text.empty() || v.scaled()) values[k].append(v.number);
      else values[k].append(v.label());
    }
    // A failed run has no results: NaN (and -1 contacts).
    const auto j = static_cast<py::ssize_t>(i);
    const bool ok = r.done && r.error.empty();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    x_r.mutable_at(j) = ok ? r.x_r : nan;
    e_r.mutable_at(j) = ok ? r.E_r : nan;
    peak.mutable_at(j) = ok ? r.peak_top : nan;
    ee.mutable_at(j) = ok ? r.elastic_energy : nan;
    contacts.mutable_at(j) = ok ? r.contacts : -1;
    status.append(!r.error.empty() ? "failed" : r.degraded ? "degraded" : "ok");
    reasons.append(r.degraded_reasons);
    errors.append(r.error);
  }
  out["keys"] = keys;
  out["values"] = py::cast(values);
  out["x_r"] = x_r;
  out["E_r"] = e_r;
  out["peak_top_displacement_m"] = peak;
  out["elastic_energy_integral"] = ee;
  out["contacts"] = contacts;
  out["status"] = status;
  out["degraded_reasons"] = reasons;
  out["error"] = errors;
  return out;
}

}  // namespace vines::python
