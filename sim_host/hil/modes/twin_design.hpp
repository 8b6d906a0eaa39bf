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
#include "vines/model/params.hpp"

namespace vines::host {

// The estimator's tuning; each default and where it comes from is in
// docs/twin.md section 4.
struct TwinTuning {
  double model_accel_sd = 0.05;  // process noise: floor accelerations the model misses [m/s^2, white over a period]
  double force_sd_mps2 = 500;    // VI NES force on its floor / floor mass: stationary sd [m/s^2]...
  double force_tau_s = 0.02;     // ...and correlation time
  double quiet_force_share = 1e-4;  // the force's sd between impacts, a share of force_sd
  double jump_sigma = 5;         // an innovation beyond this many sd switches to the impact gain...
  double jump_hold_s = 0.01;     // ...for this long
  double memory_s = 30;          // the losses' information forgets with this time constant
  double prior_sd = 0.2;         // prior sd of each loss
  double update_s = 0.05;        // parameter update period
  double max_step = 0.002;       // largest change of a loss in one update (a trust region)
  double kappa = 4;              // the TMD spring's alarm: |loss| beyond kappa sd...
  double device_loss_min = 0.1;  // ...and beyond 10 % (5 % in frequency)
  double hold_s = 2.0;           // an alarm's candidate held this long
  // The stories' decision (twin/decision.hpp): thresholds on the one-story
  // statistic (chi-square, one degree of freedom, for one test), the
  // margins naming two stories or one, the estimate's covariance inflation,
  // the change tests' drift, and the model's error without a baseline
  // (healthy stories within 3 % of the drawing, masses within 2 %, each
  // uniform).
  double threshold = 12;         // absolute test
  double threshold_change = 28;  // change tests
  double two_story = 10.8;       // a pair beyond the best story by this (chi-square 1 dof, 0.1 %)
  double two_story_share = 0.1;  // ...and by this share of the best story's statistic
  double separation = 4;         // a story named beyond the next by this
  double inflation = 1;          // the estimate's covariance times this
  double drift_sd = 0.002;       // a change test's model drift per story
  double snapshot_s = 1.0;       // the change tests' snapshots: the candidate onsets
  double calm_s = 0.4;           // a change test leaves out this long after each impact (VI NES)
  double before_sd_max = 0.02;   // a candidate onset: every story's fit before it within this sd
  double score_window_s = 2;     // the score's memory
  double misfit_level = 3;       // the score per parameter of a model that holds (section 5)...
  double misfit_memory_s = 10;   // ...beyond it, held this long, the absolute test's estimate covariance times it
  double fit_tail = 0.001;       // the absolute test's hypotheses explain the estimate: what the best leaves within
                                 // the chi-square quantile (stories - 1 degrees of freedom) of this tail
  double suspect = 60;           // the score statistic beyond this restarts the information...
  double restart_gap_s = 10;     // ...at most once in this long...
  double restart_keep = 0.3;     // ...keeping this share of it
  double healthy_tolerance = 0.03;  // no baseline: the healthy stories within this of the drawing...
  double mass_tolerance = 0.02;     // ...and the floors' masses (uniform; twin_model_error.hpp)
  double innov_window_s = 2.0;   // the innovations' running mean square
};

// A commissioning baseline (twin_baseline.hpp): the stories' losses the
// healthy building's runs identified, and their covariance.
struct TwinBaselineStats {
  std::vector<double> loss;                // per story
  std::vector<std::vector<double>> cov;    // stories x stories
  int runs = 0;                            // healthy runs it holds
};

// The bounds of each loss (1 - eta) the estimator keeps its estimates in:
// a story up to 3 times stiffer than drawn, down to a tenth of it.
constexpr double kTwinLossLow = -2.0, kTwinLossHigh = 0.9;

struct TwinDesign {
  std::vector<std::uint8_t> image;
  std::vector<double> innovation_sd;  // steady-state innovation sd per sensor [m/s^2]
  double roof_sd_m = 0;               // steady-state posterior sd of the roof displacement [m]
};

// The chi-square distribution's quantile of upper tail `tail` (0 < tail < 1,
// else throws) for k degrees of freedom; 0 for k < 1.
double chi_square_quantile(int k, double tail);

// sensors: 1-based floors; noise_sd: each sensor's noise [m/s^2 RMS];
// info: the nominal scene's built model (device design). Throws
// std::runtime_error naming the input when the design cannot be made.
// baseline: none (nullptr) leaves the nominal scene as the healthy
// building, the model's error the healthy stories' and the masses' effect
// (twin_model_error.hpp) within the tuning's tolerances; a baseline of one
// run has the masses' effect added (one record cannot show its spread).
TwinDesign design_twin(const SceneParams& nominal, const ModelInfo& info, const std::vector<int>& sensors,
                       const std::vector<double>& noise_sd, const TwinTuning& tuning,
                       const TwinBaselineStats* baseline = nullptr);

}  // namespace vines::host
