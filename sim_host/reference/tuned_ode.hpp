// The scene's right-hand side for the tuned DOP853 (dop853_tuned.cpp): the
// same model as SceneOde<double>::rhs (ode.hpp), on a frame of F floors with
// D device slots fixed at compile time (F = 0: any, from the spec), K and C
// held as their three diagonals. A frame whose K or C is not tridiagonal
// (modal damping) is computed by SceneOde itself.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "sim_host/reference/ode.hpp"
#include "vines/model/params.hpp"

namespace vines::host::reference {

template <int F, int D>
class TunedOde {
 public:
  static constexpr int kFloors = F > 0 ? F : kMaxStories;
  static constexpr int kSize = F > 0 ? 2 * (F + D) + 1 : 0;  // the state's size (0: from the spec)

  explicit TunedOde(const OdeSpec& s) : ode_(s), n_(s.frame.n), p_(ode_.size() / 2) {
    if (F > 0 && (n_ != F || p_ != F + D))
      throw std::logic_error("TunedOde: a scene of " + std::to_string(n_) + " floors, " + std::to_string(p_ - n_) +
                             " device slots, not " + std::to_string(F) + " and " + std::to_string(D));
    const HostFrame& fr = s.frame;
    for (int i = 0; i < n_; ++i) {
      inv_m_[i] = 1.0 / fr.m[static_cast<std::size_t>(i)];
      kd_[i] = fr.K_at(i, i), cd_[i] = fr.C_at(i, i);
      if (i > 0) kl_[i] = fr.K_at(i, i - 1), cl_[i] = fr.C_at(i, i - 1);
      if (i + 1 < n_) ku_[i] = fr.K_at(i, i + 1), cu_[i] = fr.C_at(i, i + 1);
      for (int j = 0; j < n_; ++j)
        if (j + 1 < i || j > i + 1) tridiagonal_ = tridiagonal_ && fr.K_at(i, j) == 0.0 && fr.C_at(i, j) == 0.0;
    }
    if (s.kind == DeviceKind::kTmd) tmd_k_ = s.tmd.k, tmd_c_ = s.tmd.c, tmd_m_ = s.tmd.mass;
    if (s.kind == DeviceKind::kVines) particle_m_ = s.vines.mass;
  }

  const SceneOde<double>& scene() const { return ode_; }
  int size() const { return F > 0 ? kSize : ode_.size(); }

  // dy/dt with ground acceleration a, in `mode`.
  void rhs(double a, const double* y, double* dy, Mode mode) const {
    if (!tridiagonal_) return ode_.rhs(a, y, dy, mode);
    const int n = F > 0 ? F : n_, p = F > 0 ? F + D : p_, f = ode_.spec().floor;
    const double* v = y + p;
    // Frame, row by row in SceneOde's order (scalar: the stage was just
    // stored, and vector loads across it would wait for the stores).
    double strain = 0.0, frame_f = 0.0;
    for (int i = 0; i < n; ++i) {
      double kx = 0.0, cv = 0.0;
      if (i > 0) kx = kl_[i] * y[i - 1], cv = cl_[i] * v[i - 1];
      kx += kd_[i] * y[i], cv += cd_[i] * v[i];
      if (i + 1 < n) kx += ku_[i] * y[i + 1], cv += cu_[i] * v[i + 1];
      strain += y[i] * kx;
      const double force = -(kx + cv);
      if (i == f) frame_f = force;
      dy[i] = v[i];
      dy[p + i] = force * inv_m_[i] - a;
    }
    // The device and its force on its floor.
    if (tmd_m_ > 0.0) {
      const double fd = tmd_k_ * (y[n] - y[f]) + tmd_c_ * (v[n] - v[f]);
      dy[p + f] = (frame_f + fd) * inv_m_[f] - a;
      dy[n] = v[n];
      dy[p + n] = -fd / tmd_m_ - a;
    } else if (particle_m_ > 0.0) {
      const double fp = mode == Mode::kFree ? 0.0 : ode_.particle_force(y, mode);
      dy[p + f] = (frame_f - fp) * inv_m_[f] - a;
      dy[n] = v[n];
      dy[p + n] = fp / particle_m_ - a;
    }
    dy[2 * p] = 0.5 * strain;
  }

 private:
  SceneOde<double> ode_;
  int n_, p_;
  bool tridiagonal_ = true;
  std::array<double, kFloors> inv_m_{}, kd_{}, kl_{}, ku_{}, cd_{}, cl_{}, cu_{};
  double tmd_k_ = 0, tmd_c_ = 0, tmd_m_ = 0, particle_m_ = 0;
};

}  // namespace vines::host::reference
