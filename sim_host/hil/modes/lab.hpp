// The lab of the shake-table mode, played by the bench: an actuator (a
// second-order servo with a pure delay) drives the table carrying the
// physical specimen, the scene's device: the VI NES (the sphere in its box,
// with the scene's contact law) or the TMD (a mass on a spring and dashpot
// fixed to the table); a load cell measures the force the specimen puts on
// the table, with noise and quantisation.
//
// Actuator: x_table(s) / x_cmd(s) = w^2 / (s^2 + 2 zeta w s + w^2) e^(-s delay),
// the command held between samples (zero-order hold). Specimen: its mass,
// relative to the ground, obeys m s'' = -m a_g + F, F the force of the table
// on it: the VI NES's contact force (the law's kernel from contact.hpp;
// finite-duration laws only), or the TMD's -k (s - x_table) - c (s' - v_table);
// the force on the table is -F. Both are integrated with classical RK4 on
// sub-steps of at most 20 us.
#pragma once

#include <deque>
#include <random>

#include "vines/model/devices.hpp"
#include "vines/model/params.hpp"

namespace vines::host {

struct LabOptions {
  double actuator_hz = 20, actuator_zeta = 0.7, delay_s = 0.005;
  double force_noise_n = 50, force_lsb_n = 10;
  unsigned long long seed = 1;
};

// What the table carries, and where its mass starts relative to the table
// (the table at rest at 0).
struct Specimen {
  DeviceKind kind = DeviceKind::kVines;  // kVines or kTmd
  VinesDesign vines;
  ContactLaw law = VinesParams{}.law;  // the scene's default
  TmdDesign tmd;
  double x0 = 0, v0 = 0;
};

class ShakeTable {
 public:
  ShakeTable(const Specimen& sp, double h, const LabOptions& opt);
  // One sensor period: the command is the one received for the sample now;
  // ground acceleration linear from a0 to a1. Returns the measured force [N].
  double advance(double command, double a0, double a1);
  double table_x() const { return x_; }
  double true_force() const { return -force_; }

 private:
  // The force of the table on the specimen's mass.
  double force_on_mass(double s, double sd, double xt, double vt) const;
  Specimen sp_;
  double mass_;
  double h_;
  LabOptions opt_;
  int sub_;
  std::deque<double> pipeline_;  // commands in flight (the pure delay), one per sub-step
  double x_ = 0, v_ = 0;         // table (actuator output) relative to the ground
  double s_ = 0, sd_ = 0;        // specimen's mass relative to the ground
  double force_ = 0;             // last force on the mass
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
};

}  // namespace vines::host
