// `vines bench --ensemble N`: work-precision over an ensemble. The response
// is chaotic, so a method is judged on N members, each run against its own
// converged reference (the long-double DOP853 of `vines reference`, on the
// same piecewise-linear input the loop reads): the mean and the 90th
// percentile of each error, how often the contact count agrees, and the cost
// of one run.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/bench/bench.hpp"

namespace vines::host {

// One member: the scene with its initial conditions or record changed.
struct EnsembleMember {
  std::string label;  // "ic u=+0.375 w=-0.625" (gap, vmax units) or the record's file name
  Scene scene;
};

// The members of an ensemble of n around a VI NES scene: up to n / 2 records
// (the AT2 files beside the scene's record, each scaled to its PGA, sphere
// as in the scene), the rest the scene's record from initial conditions of
// the 33 x 33 grid of data/studies/initial_conditions.toml (position in
// units of the free travel, speed in units of the bare frame's peak
// top-floor speed), spread over the grid. Throws std::runtime_error if the
// scene has no VI NES or n < 2.
std::vector<EnsembleMember> ensemble_members(const Scene& scene, int n);

// Mean and 90th percentile (nearest rank) of |error| over the members.
struct EnsembleStat {
  double mean = 0, p90 = 0;
};

// One line of the ensemble table: a firmware or baseline setting over every member.
struct EnsembleLine {
  BenchLine setting;  // scene, method, scheme, budget, scalar, rate, rtol
  int members = 0;
  double run_s = 0;          // mean wall time of one member's run
  EnsembleStat peak, x_r, E_r;  // peak: relative; x_r, E_r: absolute (fractions), against the bare reference
  double contacts_same = 0;  // share of members with the reference's contact count
  double contacts_diff = 0;  // mean |contacts - reference's|
};

// Every line bench_scene would give, over the members (references computed
// on opt.threads threads; the timed runs one at a time).
std::vector<EnsembleLine> bench_ensemble(const Scene& scene, const BenchOptions& opt, int n);

nlohmann::json ensemble_line_json(const EnsembleLine& l);
std::string format_ensemble_table(const std::vector<EnsembleLine>& lines);

}  // namespace vines::host
