// What a fixed-point model reports, read off its state (issue 34): every
// floor's displacement and the top floor's absolute acceleration as 64-bit
// wide dot products over the state's 2P coordinates (gain_dot), each in a
// unit of its own, then one double product: the same operations, so the
// same bits, on the host (`vines run`, the bench's offline run) and on a
// board in software floating point (its telemetry). Built once, in double,
// by probing the double model's own output functions (floor_x,
// absolute_accel: linear in the state and the device's force) with the
// fixed state's unit coordinates, so any device's state form (the modes,
// the TMD's blocks) reads the same way.
//
// Units: floor i     X_i = sum_k |x_i per unit of coordinate k|
//        top floor's absolute acceleration
//                    A = sum_k |a per unit of k| + |a per unit of force| F_u
// (a state within +-1 in every coordinate reads within +-1 of its unit).
#pragma once

#include <array>
#include <cmath>

#include <Eigen/Core>

#include "vines/fixed/frame.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/fixed_gain.hpp"
#if VINES_MODEL_REPORT
#include "vines/step/sim.hpp"
#endif

namespace vines::fixed {

template <int N, int NX>
struct FixedReadout {
  using G = numeric::Gain;
  std::array<std::array<G, NX>, N> x;  // floor i / X_i from the coordinates
  std::array<G, NX> acc;               // the top floor's absolute acceleration / A
  G acc_force;                         // ... per unit F_u of the device's force on its floor
  double x_unit[N] = {};               // X_i [m]
  double acc_unit = 0;                 // A [m/s^2]
};

// Floor i's displacement [m] of the fixed state z.
template <int N, int NX, typename Z>
double floor_x(const FixedReadout<N, NX>& r, const Z& z, int i) {
  using Q = typename Z::Scalar;
  return static_cast<double>(gain_dot<Q>(r.x[static_cast<std::size_t>(i)], z)) * r.x_unit[i];
}

// The top floor's absolute acceleration [m/s^2] of the fixed state z under
// the device's force f [F_u] on its floor.
template <int N, int NX, typename Z, typename Q>
double top_acceleration(const FixedReadout<N, NX>& r, const Z& z, Q f) {
  return static_cast<double>(gain_dot<Q>(r.acc, z, 0, f, r.acc_force)) * r.acc_unit;
}

#if VINES_MODEL_REPORT
// The readout of the double model m whose state z [SI] is to_z y for a
// fixed state y (to_z: the fixed state's units, diagonal for modes), the
// device's force in units of f_unit [N] (0: no force on the floors).
template <int N, typename Dev, int NX>
FixedReadout<N, NX> build_readout(const Model<double, N, Dev>& m,
                                  const Eigen::Matrix<double, Model<double, N, Dev>::kNx, NX>& to_z, double f_unit) {
  using G = numeric::Gain;
  Data<double, N, Dev> d{};
  Eigen::Matrix<double, N, NX> xk;
  Eigen::Matrix<double, 1, NX> ak;
  for (int k = 0; k < NX; ++k) {
    d.z = to_z.col(k);
    xk.col(k) = m.floor_x(d.z);
    ak(k) = absolute_accel(m, d)(N - 1);
  }
  d.z.setZero();
  double af = 0;
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    d.contact_force = f_unit;
    af = absolute_accel(m, d)(N - 1);
  }
  FixedReadout<N, NX> r;
  for (int i = 0; i < N; ++i) {
    r.x_unit[i] = xk.row(i).cwiseAbs().sum();
    for (int k = 0; k < NX; ++k) r.x[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = G(xk(i, k) / r.x_unit[i]);
  }
  r.acc_unit = ak.cwiseAbs().sum() + std::fabs(af);
  for (int k = 0; k < NX; ++k) r.acc[static_cast<std::size_t>(k)] = G(ak(k) / r.acc_unit);
  r.acc_force = G(af / r.acc_unit);
  return r;
}
#endif

}  // namespace vines::fixed
