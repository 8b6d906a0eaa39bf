// The lab of the shake-table mode, played by the bench: an actuator (a
// second-order servo with a pure delay) drives the table carrying the
// physical VI NES (the sphere in its box, with the scene's contact law), and a
// load cell measures the force the specimen puts on the table, with noise and
// quantisation.
//
// Actuator: x_table(s) / x_cmd(s) = w^2 / (s^2 + 2 zeta w s + w^2) e^(-s delay),
// the command held between samples (zero-order hold). Specimen: the particle,
// relative to the ground, obeys m s'' = -m a_g + F(s - x_table), F the
// contact force on it (the law's kernel from contact.hpp; finite-duration laws
// only); the force on the table is -F. Both are
// integrated with classical RK4 on sub-steps of at most 20 us.
#pragma once

#include <deque>
#include <random>

#include "vines/devices.hpp"
#include "vines/params.hpp"

namespace vines::host {

struct LabOptions {
  double actuator_hz = 20, actuator_zeta = 0.7, delay_s = 0.005;
  double force_noise_n = 50, force_lsb_n = 10;
  unsigned long long seed = 1;
};

class ShakeTable {
 public:
  ShakeTable(const VinesDesign& d, ContactLaw law, double particle_x0, double particle_v0, double h,
             const LabOptions& opt);
  // One sensor period: the command is the one received for the sample now;
  // ground acceleration linear from a0 to a1. Returns the measured force [N].
  double advance(double command, double a0, double a1);
  double table_x() const { return x_; }
  double true_force() const { return -contact_; }

 private:
  double contact_force(double s, double sd, double xt, double vt) const;
  VinesDesign d_;
  ContactLaw law_;
  double h_;
  LabOptions opt_;
  int sub_;
  std::deque<double> pipeline_;  // commands in flight (the pure delay), one per sub-step
  double x_ = 0, v_ = 0;         // table (actuator output) relative to the ground
  double s_ = 0, sd_ = 0;        // particle relative to the ground
  double contact_ = 0;           // last contact force on the particle
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
};

}  // namespace vines::host
