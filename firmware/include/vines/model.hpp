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

#include "vines/contact_laws.hpp"
#include "vines/devices.hpp"
#include "vines/frame.hpp"
#include "vines/lti.hpp"
#include "vines/params.hpp"
#include "vines/validate.hpp"

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
  S c;                      // Hertz prefactor, for the stored contact energy
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
  S hs = S(0);           // h in S

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
// otherwise: the model is then the one build_model makes from `dev`, bit for
// bit (build_model ends with this call). Finiteness is validate()'s; returns
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

#if VINES_MODEL_REPORT
namespace detail {

// Physical matrices over the P position coordinates: mass, frame stiffness,
// device spring, damping (frame dashpots and the TMD's).
template <int P>
struct Physical {
  Eigen::Matrix<double, P, P> m, k_frame, k_device, c;
};

template <int NX>
Eigen::Matrix<double, NX + 1, NX + 1> zz_form(const Eigen::Matrix<double, NX, NX>& q) {
  Eigen::Matrix<double, NX + 1, NX + 1> out = Eigen::Matrix<double, NX + 1, NX + 1>::Zero();
  out.template topLeftCorner<NX, NX>() = q;
  return out;
}

}  // namespace detail

// Builds the model in place (it can be large: keep it static). Returns the
// first problem found; the model is usable only when the result is ok().
template <typename S, int N, typename Dev>
ParamError build_model(const SceneParams& p, Model<S, N, Dev>* out) {
  using M = Model<S, N, Dev>;
  constexpr int NX = M::kNx, P = M::kP;
  Model<S, N, Dev>& md = *out;

  ParamError err = validate(p);
  if (!err.ok()) return err;
  if (p.frame.stories != N) return {"frame.stories", "does not match the compiled frame size"};
  if (p.device.kind != Dev::kKind) return {"device.kind", "does not match the compiled device"};
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    if (p.device.vines.law != Dev::kLaw)
      return {"vines.law", "does not match the compiled contact law"};
  }

  // Frame as simulated (damage applied) and nominal (devices are designed on it).
  md.frame = build_frame<N>(p.frame);
  md.modal = modal_analysis(md.frame);
  md.nominal_modal = modal_analysis(build_frame<N>(undamaged(p.frame)));
  md.loop = p.loop;
  md.h = 1.0 / p.loop.sensor_rate_hz;
  md.hs = static_cast<S>(md.h);
  md.floor = p.device.floor > 0 ? p.device.floor - 1 : N - 1;
  const double device_mass = p.device.mass_kg > 0.0
                                 ? p.device.mass_kg
                                 : p.device.mass_ratio * md.nominal_modal.m_eff(0);
  const double floor_mass = md.frame.m(md.floor);

  // Rayleigh damping fitted on two modes, zeta(w) = a0 / (2w) + a1 w / 2, goes
  // negative on the other modes when a1 < 0 or a0 < 0: they would grow
  // without bound, so the frame is refused (beyond rounding).
  for (int j = 0; j < N; ++j)
    if (p.frame.damping == DampingRule::kRayleigh && md.modal.zeta(j) < -1e-9)
      return {"frame.rayleigh_zeta",
              "gives another mode a negative damping ratio (its response would grow without "
              "bound): zeta2 / zeta1 must lie between w1 / w2 and w2 / w1 of the two modes"};

  // Classical damping is what makes the modal blocks exact: check it.
  if constexpr (M::kModal) {
    const Eigen::Matrix<double, N, N> cm = md.modal.phi.transpose() * md.frame.C * md.modal.phi;
    const double diag = cm.diagonal().cwiseAbs().maxCoeff();
    if ((cm - Eigen::Matrix<double, N, N>(cm.diagonal().asDiagonal())).cwiseAbs().maxCoeff() >
        1e-8 * (diag > 0.0 ? diag : 1.0))
      return {"frame.damping", "is not classical (modal coordinates would not decouple)"};
  }

  // Physical matrices over the position coordinates (TMD adds one).
  detail::Physical<P> ph;
  ph.m.setZero();
  ph.k_frame.setZero();
  ph.k_device.setZero();
  ph.c.setZero();
  ph.m.template topLeftCorner<N, N>() = md.frame.m.asDiagonal();
  ph.k_frame.template topLeftCorner<N, N>() = md.frame.K;
  ph.c.template topLeftCorner<N, N>() = md.frame.C;

  // Continuous-time linear part, and maps from z to positions and velocities.
  LtiSpec<NX> spec;
  spec.a.setZero();
  spec.bg.setZero();
  spec.bf.setZero();
  Eigen::Matrix<double, P, NX> px = Eigen::Matrix<double, P, NX>::Zero(), pv = px;
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    const TmdDesign t = design_tmd(p.device.tmd, device_mass, md.nominal_modal.m_eff(0),
                                   md.nominal_modal.omega(0));
    md.dev.design = t;
    const int f = md.floor, d = N;
    ph.m(d, d) = t.mass;
    ph.k_device(f, f) = ph.k_device(d, d) = t.k;
    ph.k_device(f, d) = ph.k_device(d, f) = -t.k;
    ph.c(f, f) += t.c;
    ph.c(d, d) += t.c;
    ph.c(f, d) -= t.c;
    ph.c(d, f) -= t.c;
    const Eigen::Matrix<double, P, P> minv = ph.m.diagonal().cwiseInverse().asDiagonal();
    spec.a.template topRightCorner<P, P>().setIdentity();
    spec.a.template bottomLeftCorner<P, P>() = -minv * (ph.k_frame + ph.k_device);
    spec.a.template bottomRightCorner<P, P>() = -minv * ph.c;
    spec.bg.template tail<P>().setConstant(-1.0);
    px.template leftCols<P>().setIdentity();
    pv.template rightCols<P>().setIdentity();
    md.pos_map.setZero();
    md.pos_map.template leftCols<N>().setIdentity();
  } else {
    const Modal<N>& mo = md.modal;
    for (int j = 0; j < N; ++j) {
      const double w = mo.omega(j);
      spec.a(j, P + j) = 1.0;
      spec.a(P + j, j) = -w * w;
      spec.a(P + j, P + j) = -2.0 * mo.zeta(j) * w;
      spec.bg(P + j) = -mo.gamma(j);
      spec.bf(P + j) = mo.phi(md.floor, j);
      px.col(j).template head<N>() = mo.phi.col(j);
      pv.col(P + j).template head<N>() = mo.phi.col(j);
    }
    // Padding modes j >= N: no coupling, no input, zero rows: they stay 0.
    md.pos_map.setZero();
    md.pos_map.template leftCols<N>() = mo.phi.template cast<S>();
  }
  md.rows.top = md.pos_map.row(N - 1).transpose();
  md.rows.dev = md.pos_map.row(md.floor).transpose();
  md.rows.bound = md.pos_map.cwiseAbs().colwise().maxCoeff().transpose();
  md.rows.dev_is_top = md.floor == N - 1;
  if constexpr (M::kModal) md.lti = discretise_modal<S, P>(spec, md.h);
  else md.lti = discretise_dense<S, NX>(spec, md.h);
  md.top_acc_z = pv.row(N - 1).lazyProduct(spec.a).transpose().template cast<S>();
  md.top_acc_ag = static_cast<S>(pv.row(N - 1).dot(spec.bg));

  // Energies and powers as quadratic forms in [z; a_g].
  using QX = Eigen::Matrix<double, NX, NX>;
  const auto q_kin = detail::zz_form<NX>(QX(0.5 * pv.transpose() * ph.m * pv));
  const auto q_strain = detail::zz_form<NX>(QX(0.5 * px.transpose() * ph.k_frame * px));
  const auto q_devpot = detail::zz_form<NX>(QX(0.5 * px.transpose() * ph.k_device * px));
  const auto q_damp = detail::zz_form<NX>(QX(pv.transpose() * ph.c * pv));
  // Input power -a_g (sum of m v) as a bilinear form: off-diagonal halves.
  Eigen::Matrix<double, NX + 1, NX + 1> q_in = Eigen::Matrix<double, NX + 1, NX + 1>::Zero();
  const Eigen::Matrix<double, NX, 1> mv = pv.transpose().lazyProduct(ph.m.diagonal());
  q_in.template block<NX, 1>(0, NX) = -0.5 * mv;
  q_in.template block<1, NX>(NX, 0) = -0.5 * mv.transpose();

  auto form = [](const auto& q) {
    if constexpr (M::kModal) return form_modal<S, P>(q);
    else return form_dense<S, NX>(q);
  };
  auto integral = [&](const auto& q) {
    if constexpr (M::kModal) return quad_integral_modal<S, P>(spec, q, md.h);
    else return quad_integral_dense<S, NX>(spec, q, md.h);
  };
  md.kinetic = form(q_kin);
  md.strain = form(q_strain);
  md.device_potential = form(q_devpot);
  md.damping_power = form(q_damp);
  md.input_power = form(q_in);
  md.strain_step = integral(q_strain);
  if constexpr (M::kModal) md.ee_lyapunov = lyapunov_split<S, P>(spec, q_strain, md.h, &md.rows, &md.ee_boundary);
  if (p.loop.energy_ledger) {
    md.input_step = integral(q_in);
    md.damping_step = integral(q_damp);
  }

  const Eigen::Matrix<double, N, 1> minv_frame = md.frame.m.cwiseInverse();
  md.minv_k = (minv_frame.asDiagonal() * md.frame.K).template cast<S>();
  md.minv_c = (minv_frame.asDiagonal() * md.frame.C).template cast<S>();
  md.inv_floor_mass = static_cast<S>(1.0 / floor_mass);

  if constexpr (Dev::kKind == DeviceKind::kVines) {
    const VinesParams& vp = p.device.vines;
    const VinesDesign d = design_vines(vp, device_mass, floor_mass);
    if (!d.ok)
      return {"vines.eps",
              "tau could not be calibrated for this eps and v_ref with these masses (the sphere's: "
              "device.mass_ratio or mass_kg, vines.radius_m; its floor's: frame.masses_kg)"};
    if (!(d.gap > 0.0)) return {"vines.box_length_m", "must be longer than the sphere diameter"};
    auto& dm = md.dev;
    dm.design = d;
    dm.m = static_cast<S>(d.mass);
    dm.inv_m = static_cast<S>(1.0 / d.mass);
    dm.m_star = static_cast<S>(d.m_star);
    dm.c = static_cast<S>(d.c);
    dm.eps = static_cast<S>(d.eps);
    dm.law = LawOf<Dev::kLaw>::template kernel<S>(d);
    const double v_scale = vp.v_ref_mps > 0.0 ? vp.v_ref_mps : 0.5;
    dm.pos_scale = static_cast<S>(contact::hertz_max_overlap(d.mass, d.c, v_scale));
    dm.vel_scale = static_cast<S>(v_scale);
    dm.modal_scale = static_cast<S>(std::sqrt(md.frame.m.sum()));
    dm.q_scale = static_cast<S>(std::pow(static_cast<double>(dm.pos_scale), 0.25));
    dm.ff_a0 = static_cast<S>(md.h * md.h / 3.0);
    dm.ff_a1 = static_cast<S>(md.h * md.h / 6.0);
    dm.ff_v = static_cast<S>(md.h / 2.0);
    dm.w_step0 = static_cast<S>(0.02 * std::pow(static_cast<double>(dm.pos_scale), 0.25) / v_scale);
    const double resolution = 256.0 * std::numeric_limits<S>::epsilon() * 2.0 * d.gap;
    dm.count_depth = static_cast<S>(std::fmax(p.loop.contact_count_depth_m, resolution));
  }
  return set_initial_conditions(p.device, out);
}

#endif  // VINES_MODEL_REPORT

}  // namespace vines
