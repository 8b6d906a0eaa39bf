// The immutable model: everything the loop needs, computed once from the
// scene parameters (in double) and stored in the loop's scalar S. The linear
// state z is [positions; velocities]:
//   no device, VI NES: modal coordinates [q_1..q_N, q_1'..q_N'] (modal form)
//   TMD:               physical [x_1..x_N, x_d, v_1..v_N, v_d]     (dense form)
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Core>

#include "vines/model/contact_laws.hpp"
#include "vines/model/devices.hpp"
#include "vines/model/frame.hpp"
#include "vines/model/lti.hpp"
#include "vines/model/params.hpp"
#include "vines/model/validate.hpp"

namespace vines {

// Modal coordinates are padded with inert modes (all coefficients zero) to a
// multiple of VINES_MODAL_LANES, the target's SIMD width in scalars: a step
// is then whole vector operations. 1 (no padding) unless the build sets it.
#ifndef VINES_MODAL_LANES
#define VINES_MODAL_LANES 1
#endif

// The reporting part of a model (the frame as simulated, its modes, the
// nominal modes) is read by host summaries and by build_model, never by the
// loop. A board that receives its model as an image (model_image.hpp)
// compiles without it (VINES_MODEL_REPORT 0): it holds less RAM and cannot
// build a model at all, which is the point.
#ifndef VINES_MODEL_REPORT
#define VINES_MODEL_REPORT 1
#endif

template <typename Dev, int N>
struct Layout {
  static constexpr bool kModal = true;
  static constexpr int kLanes = VINES_MODAL_LANES;
  static constexpr int kP = (N + kLanes - 1) / kLanes * kLanes;  // position coordinates
  static constexpr int kNx = 2 * kP;
};
template <int N>
struct Layout<TmdDevice, N> {
  static constexpr bool kModal = false;
  static constexpr int kNx = 2 * (N + 1), kP = N + 1;
};

// Device constants in the loop's scalar.
template <typename S, typename Dev>
struct DeviceModel {};

template <typename S>
struct DeviceModel<S, TmdDevice> {
  TmdDesign design;
  S x0 = S(0), v0 = S(0);  // initial TMD state relative to its floor
};

template <typename S, ContactLaw L>
struct DeviceModel<S, VinesDevice<L>> {
  VinesDesign design;
  S m, m_star, inv_m;
  S wall_left, wall_right;  // in the particle coordinate s (see below)
  S y0, v0;                 // initial position (from the box centre) and velocity
  S c;                      // Hertz prefactor (reports and the image; the law's kernel has its own)
  S eps;
  // The law's kernel (contact_laws.hpp; unused for the instantaneous law).
  typename LawOf<L>::template Kernel<S> law;
  // Error scales of the sub-stepper: a position and a speed typical of
  // contacts, q = d^{1/4} of that position, and a first step in w (q moves
  // by ~2 % of its scale).
  S pos_scale, vel_scale, modal_scale, q_scale, w_step0;
  // Exact free flight over a sensor step under -a_g linear from a0 to a1:
  // s1 = s + h s' - ff_a0 a0 - ff_a1 a1, s1' = s' - ff_v (a0 + a1).
  S ff_a0, ff_a1, ff_v;
  // Contacts shallower than this are not counted: the scene's depth, but no
  // less than what the scalar resolves across the box (rounding fakes them).
  S count_depth;
  // Overlaps below event_tol [m] do not start a contact: rounding makes them
  // when the particle rests against a wall, and chasing them only churns
  // events. round_tol covers the rounding of the relative position s - x_f.
  // A free step stays clear of the walls while s - x_f stays inside
  // (clear_lo, clear_hi): the walls widened by event_tol.
  S event_tol, round_tol, clear_lo, clear_hi;
  // The sphere's radius [m] in S (the divergence check's margin beyond a wall).
  S radius;
};

template <typename S, int N, typename Dev>
struct Model {
  static constexpr bool kModal = Layout<Dev, N>::kModal;
  static constexpr int kNx = Layout<Dev, N>::kNx;
  static constexpr int kP = Layout<Dev, N>::kP;
  using VecX = Eigen::Matrix<S, kNx, 1>;
  using VecN = Eigen::Matrix<S, N, 1>;
  using VecP = Eigen::Matrix<S, kP, 1>;
  using LtiT = std::conditional_t<kModal, ModalLti<S, kP>, DenseLti<S, kNx>>;
  using QuadT = std::conditional_t<kModal, ModalQuad<S, kP>, DenseQuad<S, kNx>>;
  using FormT = std::conditional_t<kModal, ModalForm<S, kP>, DenseForm<S, kNx>>;

#if VINES_MODEL_REPORT
  // Reporting (double): the frame as simulated, its modes, the nominal modes.
  Frame<N> frame;
  Modal<N> modal;
  Modal<N> nominal_modal;
#endif
  LoopParams loop;
  double h = 0;          // sensor period [s]
  int floor = N - 1;     // device floor, 0-based
  S period = S(0);       // h in S
  // The loop's settings the step reads, in S (no conversion from double on
  // the step: on a single-precision FPU that is a library call):
  // loop.divergence_limit_m, and loop.contact_rtol no finer than the scalar
  // honours (64 eps).
  S divergence_limit = S(0);
  S contact_rtol = S(0);

  // Exact step and exact step integrals of the linear part.
  LtiT lti;
  QuadT strain_step;   // integral of (1/2) x^T K x: E_e
  QuadT input_step;    // input work of the linear part's masses
  QuadT damping_step;  // dashpot dissipation
  // Instantaneous forms: energies and powers.
  FormT kinetic, strain, device_potential, damping_power, input_power;

  // Floors from z: x = pos_map * (position coordinates), likewise v. rows:
  // the rows of the top floor and the device floor (contiguous), the floor
  // bound's, and (modal form) the E_e linear form of the fused exact step
  // (step_read); E_e by the Lyapunov split when every mode is damped,
  // ee_boundary being its V(z) (see lyapunov_split).
  Eigen::Matrix<S, N, kP> pos_map;
  ModalRows<S, kP> rows;
  bool ee_lyapunov = false;
  ModalForm<S, kP> ee_boundary;
  // The top floor's acceleration relative to the ground with no device
  // force: top_acc_z . z + top_acc_ag a_g (a row of the linear part).
  VecX top_acc_z = VecX::Zero();
  S top_acc_ag = S(0);
  // Absolute floor acceleration: -(M^-1 K) x - (M^-1 C) v + (force on floor f) / m_f.
  Eigen::Matrix<S, N, N> minv_k, minv_c;
  S inv_floor_mass = S(0);

  DeviceModel<S, Dev> dev;

  // z may be any expression of kNx values (a segment of a longer state).
  template <typename Z>
  VecN floor_x(const Eigen::MatrixBase<Z>& z) const { return pos_map.lazyProduct(z.template head<kP>()); }
  template <typename Z>
  VecN floor_v(const Eigen::MatrixBase<Z>& z) const { return pos_map.lazyProduct(z.template tail<kP>()); }
  // Top floor and device floor (the hot path).
  template <typename Z>
  S top_x(const Eigen::MatrixBase<Z>& z) const { return rows.top.dot(z.template head<kP>()); }
  template <typename Z>
  S top_v(const Eigen::MatrixBase<Z>& z) const { return rows.top.dot(z.template tail<kP>()); }
  template <typename Z>
  S top_a(const Eigen::MatrixBase<Z>& z, S ag) const { return top_acc_z.dot(z) + top_acc_ag * ag; }
  template <typename Z>
  S dev_x(const Eigen::MatrixBase<Z>& z) const { return rows.dev.dot(z.template head<kP>()); }
  template <typename Z>
  S dev_v(const Eigen::MatrixBase<Z>& z) const { return rows.dev.dot(z.template tail<kP>()); }
  // A cheap bound on the largest |floor displacement|: sum of |q_j| max_i |phi_ij|.
  template <typename Z>
  S floor_bound(const Eigen::MatrixBase<Z>& z) const {
    return rows.bound.dot(z.template head<kP>().cwiseAbs());
  }
};

// Sets the device's initial conditions (TMD: x0, v0; VI NES: where the
// particle starts, its speed, and the wall coordinates and tolerances that
// follow from where it starts) in a model built from the same parameters
// otherwise: the model is then the one build_model (build_model.hpp) makes
// from `dev`, bit for bit (build_model ends with this call). Finiteness is validate()'s; returns
// the first problem found. Needs only the device design and md.loop, so a
// model loaded from an image can take new initial conditions too.
template <typename S, int N, typename Dev>
ParamError set_initial_conditions(const DeviceParams& dev, Model<S, N, Dev>* out) {
  Model<S, N, Dev>& md = *out;
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    md.dev.x0 = static_cast<S>(dev.tmd.initial_position_m);
    md.dev.v0 = static_cast<S>(dev.tmd.initial_velocity_mps);
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    const VinesParams& vp = dev.vines;
    auto& dm = md.dev;
    const double gap = dm.design.gap;
    const double y0 = vp.start_at_left_wall ? -gap : vp.initial_position_m;
    if (std::fabs(y0) > gap) return {"vines.initial_position_m", "must lie within the free travel (-gap, +gap)"};
    // The particle is carried as s = y - y0, its displacement (relative to the
    // ground) from where it starts; the walls are at r = s - x_floor equal to
    // -gap - y0 and gap - y0. Starting on the left wall, that wall is at 0
    // exactly: no cancellation fakes sub-nanometre contacts.
    dm.wall_left = static_cast<S>(-gap - y0);
    dm.wall_right = static_cast<S>(gap - y0);
    dm.y0 = static_cast<S>(y0);
    dm.v0 = static_cast<S>(vp.initial_velocity_mps);
    constexpr S kEps = std::numeric_limits<S>::epsilon();
    const S rtol = std::fmax(static_cast<S>(md.loop.contact_rtol), S(64) * kEps);
    dm.event_tol = std::fmax(rtol * dm.pos_scale * S(1e-2), S(64) * kEps * (dm.wall_right - dm.wall_left));
    dm.round_tol = S(16) * kEps * (dm.wall_right - dm.wall_left);
    dm.clear_lo = dm.wall_left - dm.event_tol;
    dm.clear_hi = dm.wall_right + dm.event_tol;
  }
  return {};
}

}  // namespace vines
