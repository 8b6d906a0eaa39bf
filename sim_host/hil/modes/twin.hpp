// The twin bench (docs/twin.md): the measured building simulated from its own
// scene (the truth), its floor accelerometers with noise, bias and ADC
// quantisation drawn from the seed, and the estimator's design the node is
// sent. What the twin mode streams, and what its report holds the node's
// estimates against.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sim_host/hil/modes/twin_design.hpp"
#include "sim_host/hil/options.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {

// The truth's run, step by step, as the report needs it.
struct TwinTruth {
  std::string path;                 // its scene ("" : the node's scene, scaled)
  std::vector<double> story_scale;  // each story's stiffness factor (eta_k x its own)
  // Its [damage]: when it struck (the sample at damage.time_s; none without
  // one) and each story's factor from then on (story_scale without one).
  std::optional<double> damage_time_s;
  std::vector<double> damaged_story_scale;
  std::vector<double> roof_x;       // top-floor displacement [m]
  std::vector<double> device_force; // VI NES: the device's force on its floor [N]; TMD, none: 0
  double tmd_frequency_factor = 1;  // truth TMD frequency / the node's design
  double particle_mass = 0;         // the node's VI NES sphere [kg] (its design)
  double particle_gap = 0;          // ...its free travel each side of the box's centre [m]
  long long contacts = 0;
};

struct TwinBench {
  std::vector<int> sensors;          // 1-based floors
  std::vector<double> noise_sd;      // per sensor [m/s^2 RMS]
  std::vector<std::vector<double>> y;  // y[k]: the sensors' readings at sample k
  std::vector<double> top;           // the top floor's reading (the open-loop twin's aux)
  TwinTruth truth;
  TwinDesign design;                 // estimator kalman only
  double strong_motion_start_s = 0;  // the record's 5 % Arias intensity time
  // Where a detection's delay counts from: the truth's damage time when it
  // has one, else the strong motion's start.
  double delay_origin_s() const { return truth.damage_time_s ? *truth.damage_time_s : strong_motion_start_s; }
};

// Checks the twin options against the scene (sensors, noise, truth: same
// story count, sensor rate and record; no [damage] in the node's scene, the
// nominal model) and runs the truth (with its [damage], switched to the
// damaged building at damage.time_s); throws
// std::runtime_error naming the input.
TwinBench make_twin_bench(const Scene& scene, const HilOptions& opt, const Excitation& ex);

}  // namespace vines::host
