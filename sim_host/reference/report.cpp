#include "sim_host/reference/report.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vines::host::reference {
namespace {

using nlohmann::json;

// Largest shift of a contact start between two runs (null if the counts differ).
json start_shift(const Result& a, const Result& b) {
  if (a.contact_start_s.size() != b.contact_start_s.size()) return nullptr;
  double m = 0.0;
  for (std::size_t i = 0; i < a.contact_start_s.size(); ++i)
    m = std::max(m, std::fabs(a.contact_start_s[i] - b.contact_start_s[i]));
  return m;
}

json convergence(const Result& fine, const Result& coarse, double rtol_coarse) {
  return {{"rtol_coarse", rtol_coarse},
          {"peak_rel_diff", rel_diff(coarse.peak_top, fine.peak_top)},
          {"t_peak_diff_s", std::fabs(coarse.t_peak_top - fine.t_peak_top)},
          {"elastic_energy_rel_diff", rel_diff(coarse.elastic_energy, fine.elastic_energy)},
          {"contacts_equal", coarse.contacts == fine.contacts},
          {"contact_start_max_diff_s", start_shift(fine, coarse)},
          {"max_overlap_rel_diff", rel_diff(coarse.max_overlap, fine.max_overlap)}};
}

// The record's own knots when the sensor grid holds them (every m-th sample):
// the same ground motion, but steps the controller chooses up to dt instead
// of steps pinned to the sensor period. Empty when the grids do not nest.
std::vector<double> knots(const Excitation& ex, double* rate) {
  const double per = ex.rate_hz * ex.record.dt_s, t0 = ex.record.t0_s / ex.record.dt_s;
  const auto m = static_cast<std::size_t>(std::llround(per));
  const std::size_t n = ex.samples.size() - 1;
  if (m < 2 || std::fabs(per - static_cast<double>(m)) > 1e-9 * per || std::fabs(t0 - std::round(t0)) > 1e-9 ||
      n % m != 0)
    return {};
  std::vector<double> out;
  for (std::size_t k = 0; k <= n; k += m) out.push_back(ex.samples[k]);
  *rate = ex.rate_hz / static_cast<double>(m);
  return out;
}

}  // namespace

ReferenceReport reference_report(const Scene& scene, double rtol) {
  const Excitation ex = load_excitation(scene, "");
  const SceneParams& p = scene.params;
  Options fine;
  fine.rtol = rtol;
  const auto run = [&](const SceneParams& sp, const Options& o) {
    try {
      return integrate(sp, ex.samples, ex.rate_hz, Method::kReference, o);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(scene.path + ": " + e.what());
    }
  };
  ReferenceReport rep;
  rep.scene = scene.name;
  rep.scene_file = scene.path;
  rep.record = {scene.record.path, ex.record.dt_s, ex.record.accel_mps2.size(), ex.record.pga_mps2(),
                static_cast<double>(ex.samples.size() - 1) / ex.rate_hz};
  rep.sample_rate_hz = ex.rate_hz;
  // The scene at the tolerance and at 100 times it; its bare frame the same.
  rep.run = run(p, fine);
  rep.rtol = rtol > 0.0 ? rtol : 1e-15;
  Options coarse_opt = fine;
  coarse_opt.rtol = 100.0 * rep.rtol;
  rep.rtol_coarse = coarse_opt.rtol;
  rep.coarse = run(p, coarse_opt);
  const bool has_device = p.device.kind != DeviceKind::kNone;
  SceneParams pb = p;
  pb.device.kind = DeviceKind::kNone;
  rep.bare = has_device ? run(pb, fine) : rep.run;
  rep.bare_coarse = has_device ? run(pb, coarse_opt) : rep.coarse;
  // At the sensor rate the linear scenes take one step per sample at both
  // tolerances; the knot run is the check that moves their steps.
  double knot_rate = 0.0;
  const std::vector<double> k = knots(ex, &knot_rate);
  if (!k.empty()) rep.knots = KnotRun{knot_rate, integrate(p, k, knot_rate, Method::kReference, fine)};
  return rep;
}

json ReferenceReport::to_json() const {
  const Result& r = run;
  json j;
  j["scene"] = scene;
  j["scene_file"] = scene_file;
  j["record"] = {{"path", record.path},  // as the scene names it (resolved at run time)
                 {"dt_s", record.dt_s},
                 {"points", record.points},
                 {"pga_mps2", record.pga_mps2},
                 {"sample_rate_hz", sample_rate_hz},
                 {"simulated_s", record.simulated_s}};
  j["method"] = method_name(Method::kReference);
  j["rtol"] = rtol;
  j["peak_top_displacement_m"] = r.peak_top;
  j["t_peak_top_s"] = r.t_peak_top;
  j["elastic_energy_Js"] = r.elastic_energy;
  j["contacts"] = r.contacts;
  j["contact_starts_s"] = r.contact_start_s;
  j["max_overlap_m"] = r.max_overlap;
  j["bare"] = {{"peak_top_displacement_m", bare.peak_top},
               {"t_peak_top_s", bare.t_peak_top},
               {"elastic_energy_Js", bare.elastic_energy}};
  j["x_r"] = x_r();
  j["E_r"] = E_r();
  j["convergence"] = convergence(r, coarse, rtol_coarse);
  j["convergence"]["bare"] = convergence(bare, bare_coarse, rtol_coarse);
  if (!knots) {
    j["convergence"]["knots"] = nullptr;
  } else {
    const Result& rk = knots->result;
    j["convergence"]["knots"] = {{"sample_rate_hz", knots->sample_rate_hz},
                                 {"steps", rk.steps},
                                 {"peak_rel_diff", rel_diff(rk.peak_top, r.peak_top)},
                                 {"elastic_energy_rel_diff", rel_diff(rk.elastic_energy, r.elastic_energy)},
                                 {"contacts_equal", rk.contacts == r.contacts},
                                 {"contact_start_max_diff_s", start_shift(r, rk)}};
  }
  j["wall_s"] = r.wall_s;
  j["steps"] = r.steps;
  j["rejected"] = r.rejected;
  j["rhs_evals"] = r.rhs_evals;
  j["events"] = r.events;
  return j;
}

}  // namespace vines::host::reference
