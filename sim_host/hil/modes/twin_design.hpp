// The twin estimator's design on the host (docs/twin.md): the nominal
// frame (with the TMD as a mass, or the VI NES force as an unknown input),
// discretised exactly at the sensor period, its steady-state Kalman gain for
// the chosen floor accelerometers, and the damage patterns of each spring,
// written as the twin image (vines/twin/image.hpp) a twin node runs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim_host/engines/engine.hpp"
#include "vines/params.hpp"

namespace vines::host {

// The estimator's tuning; each default and where it comes from is in
// docs/twin.md section 4.
struct TwinTuning {
  double model_accel_sd = 0.05;  // process noise: floor accelerations the model misses [m/s^2, white over a period]
  double force_sd_mps2 = 2.0;    // VI NES force on its floor / floor mass: stationary sd [m/s^2]...
  double force_tau_s = 0.02;     // ...and correlation time
  double quiet_force_share = 0.05;  // the force's sd between impacts, a share of force_sd
  double jump_sigma = 5;         // an innovation beyond this many sd switches to the impact gain...
  double jump_hold_s = 0.01;     // ...for this long
  double memory_s = 30;          // the losses' information forgets with this time constant
  double prior_sd = 0.2;         // prior sd of each loss
  double update_s = 0.05;        // parameter update period
  double max_step = 0.002;       // largest change of a loss in one update (a trust region)
  double kappa = 4;              // alarm: loss beyond kappa sd...
  double loss_min = 0.05;        // ...and beyond 5 % (stories)
  double device_loss_min = 0.1;  // the TMD spring: |loss| beyond 10 % (5 % in frequency)
  double hold_s = 2.0;           // held this long
  double innov_window_s = 2.0;   // the innovations' running mean square
};

struct TwinDesign {
  std::vector<std::uint8_t> image;
  std::vector<double> innovation_sd;  // steady-state innovation sd per sensor [m/s^2]
  double roof_sd_m = 0;               // steady-state posterior sd of the roof displacement [m]
};

// sensors: 1-based floors; noise_sd: each sensor's noise [m/s^2 RMS];
// info: the nominal scene's built model (device design). Throws
// std::runtime_error naming the input when the design cannot be made.
TwinDesign design_twin(const SceneParams& nominal, const ModelInfo& info, const std::vector<int>& sensors,
                       const std::vector<double>& noise_sd, const TwinTuning& tuning);

}  // namespace vines::host
