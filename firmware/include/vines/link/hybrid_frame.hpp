// The frame of a real-time hybrid simulation: the bare shear frame (no device)
// with an external force F on the top floor, measured on the shake table.
// In modal coordinates (mass-normalised shapes phi, classical damping) each
// mode obeys  q'' + 2 zeta w q' + w^2 q = -gamma a_g(t) + phi_top F(t);
// a_g and F are both taken linear over a step (first-order hold, like the core
// loop's ground acceleration), so every mode is stepped exactly by a 2x2
// transition and two input columns (lti.hpp's first-order-hold step).
// No heap; n <= kMaxStories at run time.
#pragma once

#include <Eigen/Core>

#include "vines/lti.hpp"
#include "vines/params.hpp"

namespace vines::link {

// Modal data of a frame: modes j, floors i (bottom first).
struct ModalData {
  int n = 0;
  double omega[kMaxStories] = {}, zeta[kMaxStories] = {}, gamma[kMaxStories] = {};
  double phi[kMaxStories][kMaxStories] = {};  // phi[i][j]: floor i in mode j
};

template <typename S>
class HybridFrame {
 public:
  void setup(const ModalData& md, double h) {
    md_ = md;
    h_ = h;
    for (int j = 0; j < md.n; ++j) {
      const double w = md.omega[j], z = md.zeta[j];
      Eigen::Matrix2d a;
      a << 0, 1, -w * w, -2 * z * w;
      // The core loop's exact FOH step, with the modal input u as the input.
      const vines::detail::Foh<2> f = vines::detail::foh<2>(a, Eigen::Vector2d(0, 1), h);
      for (int r = 0; r < 2; ++r) {
        for (int c = 0; c < 2; ++c) phi_t_[j][r][c] = static_cast<S>(f.phi(r, c));
        g0_[j][r] = static_cast<S>(f.g0(r));
        g1_[j][r] = static_cast<S>(f.g1(r));
      }
    }
  }

  void init(double a0, double f0) {
    for (int j = 0; j < md_.n; ++j) q_[j] = qd_[j] = S(0);
    u_prev_a_ = a0;
    u_prev_f_ = f0;
    elastic_energy_ = 0;
    strain_ = 0;
  }

  void step(double a1, double f1) {
    const int n = md_.n, top = n - 1;
    for (int j = 0; j < n; ++j) {
      const S u0 = static_cast<S>(-md_.gamma[j] * u_prev_a_ + md_.phi[top][j] * u_prev_f_);
      const S u1 = static_cast<S>(-md_.gamma[j] * a1 + md_.phi[top][j] * f1);
      const S q = q_[j], qd = qd_[j];
      q_[j] = phi_t_[j][0][0] * q + phi_t_[j][0][1] * qd + g0_[j][0] * u0 + g1_[j][0] * u1;
      qd_[j] = phi_t_[j][1][0] * q + phi_t_[j][1][1] * qd + g0_[j][1] * u0 + g1_[j][1] * u1;
    }
    u_prev_a_ = a1;
    u_prev_f_ = f1;
    // E_e by the trapezoidal rule on the strain energy (1/2) sum w^2 q^2.
    double strain = 0;
    for (int j = 0; j < n; ++j) strain += 0.5 * md_.omega[j] * md_.omega[j] * static_cast<double>(q_[j] * q_[j]);
    elastic_energy_ += 0.5 * h_ * (strain + strain_);
    strain_ = strain;
  }

  // Floor displacement i [m] relative to the ground.
  double x(int i) const {
    double v = 0;
    for (int j = 0; j < md_.n; ++j) v += md_.phi[i][j] * static_cast<double>(q_[j]);
    return v;
  }
  // Absolute acceleration of floor i [m/s^2] now.
  double abs_acc(int i) const {
    double v = u_prev_a_;
    for (int j = 0; j < md_.n; ++j) {
      const double w = md_.omega[j];
      const double u = -md_.gamma[j] * u_prev_a_ + md_.phi[md_.n - 1][j] * u_prev_f_;
      v += md_.phi[i][j] * (u - 2 * md_.zeta[j] * w * static_cast<double>(qd_[j]) - w * w * static_cast<double>(q_[j]));
    }
    return v;
  }
  double elastic_energy() const { return elastic_energy_; }
  int stories() const { return md_.n; }

 private:
  ModalData md_;
  S phi_t_[kMaxStories][2][2] = {}, g0_[kMaxStories][2] = {}, g1_[kMaxStories][2] = {};
  S q_[kMaxStories] = {}, qd_[kMaxStories] = {};
  double u_prev_a_ = 0, u_prev_f_ = 0, elastic_energy_ = 0, strain_ = 0, h_ = 0;
};

}  // namespace vines::link
