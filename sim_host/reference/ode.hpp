// The scene as a piecewise-smooth ODE in physical coordinates, templated on
// the scalar (long double for the reference, double for CVODE). State:
//   [x_1..x_N, (x_d), v_1..v_N, (v_d), E_e]
// relative to the ground; x_d is the TMD's displacement, or the particle's
// displacement w from where it starts (walls at r = w - x_floor equal to
// wall_left, wall_right). E_e = integral of (1/2) x^T K_frame x dt.
// Every mass carries -m a_g. The smooth pieces are the modes below; the
// integrators switch between them at located events, by the firmware's
// contact-mode state machine (take_event in integrators.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "sim_host/reference/spec.hpp"
#include "vines/model/contact.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/contact_mode.hpp"

namespace vines::host::reference {

// The particle's modes and the plastic-impact speed are the firmware's
// (contact_mode.hpp): below kStickSpeed an instantaneous impact is plastic
// and the particle rides the wall.
using vines::kStickSpeed;
using vines::Mode;

template <typename T>
class SceneOde {
 public:
  explicit SceneOde(const OdeSpec& s)
      : spec_(s), n_(s.frame.n), p_(s.kind == DeviceKind::kNone ? n_ : n_ + 1), f_(s.floor) {
    for (int i = 0; i < n_; ++i) {
      inv_m_.push_back(T(1) / T(s.frame.m[static_cast<std::size_t>(i)]));
      // Non-zero band of row i of K and C (tridiagonal for the usual rules).
      int lo = n_, hi = -1;
      for (int j = 0; j < n_; ++j)
        if (s.frame.K_at(i, j) != 0.0 || s.frame.C_at(i, j) != 0.0) lo = std::min(lo, j), hi = std::max(hi, j);
      band_lo_.push_back(lo);
      band_hi_.push_back(hi);
    }
    for (double v : s.frame.K) K_.push_back(T(v));
    for (double v : s.frame.C) C_.push_back(T(v));
    const VinesDesign& d = s.vines;
    m_dev_ = T(s.kind == DeviceKind::kTmd ? s.tmd.mass : d.mass);
    m_floor_ = T(s.frame.m[static_cast<std::size_t>(f_)]);
    m_star_ = T(d.m_star);
    eps_ = T(d.eps);
    wall_left_ = T(s.wall_left);
    wall_right_ = T(s.wall_right);
    // Overlaps below this do not start a contact: rounding of the relative
    // position across the box (a particle resting on a wall would otherwise
    // start sub-attometre "contacts" at every step).
    start_depth_ = T(32) * std::numeric_limits<T>::epsilon() * (wall_right_ - wall_left_);
  }

  const OdeSpec& spec() const { return spec_; }
  int size() const { return 2 * p_ + 1; }
  int floors() const { return n_; }
  bool has_particle() const { return spec_.kind == DeviceKind::kVines; }
  bool restitution() const { return has_particle() && law_impulsive(spec_.law); }
  int energy_index() const { return 2 * p_; }
  T top_x(const T* y) const { return y[n_ - 1]; }
  T top_v(const T* y) const { return y[p_ + n_ - 1]; }
  T start_depth() const { return start_depth_; }

  // Error scales [m, m/s, J s]: absolute tolerance = rtol * scale.
  std::vector<T> scales() const {
    const T x = T(1e-3), v = T(1e-2), e = T(0.5) * K_[0] * x * x;
    std::vector<T> s(static_cast<std::size_t>(size()), x);
    for (int i = p_; i < 2 * p_; ++i) s[static_cast<std::size_t>(i)] = v;
    s[static_cast<std::size_t>(energy_index())] = e;
    return s;
  }

  void initial_state(T* y) const {
    for (int i = 0; i < size(); ++i) y[i] = T(0);
    if (spec_.kind == DeviceKind::kTmd) {
      y[n_] = T(spec_.tmd_x0);
      y[p_ + n_] = T(spec_.tmd_v0);
    }
    if (has_particle()) y[p_ + n_] = T(spec_.v0);
  }

  // Particle relative to the device floor, and the overlap with wall `side`
  // (-1 left, +1 right) and its rate; positive means interpenetration.
  T rel_pos(const T* y) const { return y[n_] - y[f_]; }
  T rel_vel(const T* y) const { return y[p_ + n_] - y[p_ + f_]; }
  T overlap(const T* y, int side) const { return side < 0 ? wall_left_ - rel_pos(y) : rel_pos(y) - wall_right_; }
  T overlap_rate(const T* y, int side) const { return side < 0 ? -rel_vel(y) : rel_vel(y); }

  // Force of the wall on a particle riding it (positive to the right): what
  // gives the particle the floor's acceleration, m* (frame force on the floor) / m_floor.
  T holding_force(const T* y) const { return m_star_ * frame_force(y, f_) / m_floor_; }

  // Force on the particle (positive to the right) in `mode`.
  T particle_force(const T* y, Mode mode) const {
    switch (mode) {
      case Mode::kContactLeft:
      case Mode::kContactRight: {
        const int side = mode == Mode::kContactLeft ? -1 : 1;
        const T d = overlap(y, side);
        if (!(d > T(0))) return T(0);
        const T f = law_force(d, overlap_rate(y, side));
        return side < 0 ? f : -f;
      }
      case Mode::kStuckLeft:
      case Mode::kStuckRight:
        return holding_force(y);
      default:
        return T(0);
    }
  }

  // dy/dt with ground acceleration a.
  void rhs(T a, const T* y, T* dy, Mode mode) const {
    const T* v = y + p_;
    T strain = T(0);
    for (int i = 0; i < n_; ++i) {
      T kx = T(0), cv = T(0);
      const std::size_t row = static_cast<std::size_t>(i * n_);
      for (int j = band_lo_[static_cast<std::size_t>(i)]; j <= band_hi_[static_cast<std::size_t>(i)]; ++j) {
        kx += K_[row + j] * y[j];
        cv += C_[row + j] * v[j];
      }
      strain += y[i] * kx;
      dy[i] = v[i];
      dy[p_ + i] = -(kx + cv);  // force for now; divided by the mass below
    }
    if (spec_.kind == DeviceKind::kTmd) {
      const T fd = T(spec_.tmd.k) * (y[n_] - y[f_]) + T(spec_.tmd.c) * (v[n_] - v[f_]);
      dy[p_ + f_] += fd;
      dy[n_] = v[n_];
      dy[p_ + n_] = -fd / m_dev_ - a;
    } else if (has_particle()) {
      const T fp = particle_force(y, mode);
      dy[p_ + f_] -= fp;
      dy[n_] = v[n_];
      dy[p_ + n_] = fp / m_dev_ - a;
    }
    for (int i = 0; i < n_; ++i) dy[p_ + i] = dy[p_ + i] * inv_m_[static_cast<std::size_t>(i)] - a;
    dy[energy_index()] = T(0.5) * strain;
  }

  // Instantaneous impact on wall `side` at approach speed v_app > 0 (Newton's
  // law between the particle and the floor mass, Eq. 4). Returns true when
  // the impact was plastic (the particle should ride the wall).
  bool impact(T* y, int side, T v_app) const {
    const bool plastic = eps_ * v_app < T(kStickSpeed);
    const T j = contact::restitution_impulse(m_dev_, m_floor_, v_app, plastic ? T(0) : eps_);
    const T jp = side < 0 ? j : -j;  // on the particle
    y[p_ + n_] += jp / m_dev_;
    y[p_ + f_] -= jp / m_floor_;
    return plastic;
  }

 private:
  T frame_force(const T* y, int i) const {
    T f = T(0);
    const std::size_t row = static_cast<std::size_t>(i * n_);
    for (int j = band_lo_[static_cast<std::size_t>(i)]; j <= band_hi_[static_cast<std::size_t>(i)]; ++j)
      f -= K_[row + j] * y[j] + C_[row + j] * y[p_ + j];
    return f;
  }

  // The force of the scene's law (contact_laws.hpp), in T.
  T law_force(T d, T dd) const {
    T f = T(0);
    with_law(spec_.law, [&](auto law) { f = decltype(law)::template kernel<T>(spec_.vines)(d, dd).total(); });
    return f;
  }

  OdeSpec spec_;
  int n_, p_, f_;
  std::vector<T> K_, C_, inv_m_;
  std::vector<int> band_lo_, band_hi_;
  T m_dev_ = T(0), m_floor_ = T(0), m_star_ = T(0), eps_ = T(1);
  T wall_left_ = T(0), wall_right_ = T(0), start_depth_ = T(0);
};

}  // namespace vines::host::reference
