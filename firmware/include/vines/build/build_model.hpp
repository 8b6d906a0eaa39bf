// Building the immutable model (model.hpp) from the scene parameters, once,
// in double. build_model reads as its stages:
//   1. check_compiled   the scene fits the compiled frame size, device, law
//   2. build_frames     the frame as simulated and nominal, their modes, the
//                       sensor period; frames whose damping the loop cannot
//                       take are refused
//   3. linear_part      the continuous-time linear part over the position
//                       coordinates: physical matrices, the state equation,
//                       the maps from z to positions and velocities (TMD:
//                       its design and its degree of freedom)
//   4. discretise       the exact step, the rows the loop reads, the top
//                       floor's acceleration row
//   5. energy_forms     energies and powers as forms, their step integrals
//                       (the ledger's only when the scene asks for it)
//   6. build_vines      the VI NES design, its constants in S, the
//                       sub-stepper's scales
//   7. set_initial_conditions (model.hpp)
// A board that receives its model as an image compiles none of this
// (VINES_MODEL_REPORT 0, model.hpp).
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "vines/build/lti_build.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/devices.hpp"
#include "vines/model/frame.hpp"
#include "vines/model/model.hpp"
#include "vines/model/params.hpp"
#include "vines/model/validate.hpp"

#if VINES_MODEL_REPORT
namespace vines {

namespace detail {

// The continuous-time linear part over the P position coordinates (stage 3).
template <int NX, int P>
struct LinearPart {
  // Physical matrices: mass, frame stiffness, device spring, damping (frame
  // dashpots and the TMD's).
  Eigen::Matrix<double, P, P> m, k_frame, k_device, c;
  LtiSpec<NX> spec;
  // Positions px z and velocities pv z of the P coordinates.
  Eigen::Matrix<double, P, NX> px, pv;
};

template <int NX>
Eigen::Matrix<double, NX + 1, NX + 1> zz_form(const Eigen::Matrix<double, NX, NX>& q) {
  Eigen::Matrix<double, NX + 1, NX + 1> out = Eigen::Matrix<double, NX + 1, NX + 1>::Zero();
  out.template topLeftCorner<NX, NX>() = q;
  return out;
}

// 1. The scene is the one this model type was compiled for.
template <typename S, int N, typename Dev>
ParamError check_compiled(const SceneParams& p) {
  if (p.frame.stories != N) return {"frame.stories", "does not match the compiled frame size"};
  if (p.device.kind != Dev::kKind) return {"device.kind", "does not match the compiled device"};
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    if (p.device.vines.law != Dev::kLaw) return {"vines.law", "does not match the compiled contact law"};
  }
  return {};
}

// 2. Frame as simulated (damage applied) and nominal (devices are designed
// on it), the sensor period, the device floor.
template <typename S, int N, typename Dev>
ParamError build_frames(const SceneParams& p, Model<S, N, Dev>& md) {
  md.frame = build_frame<N>(p.frame);
  md.modal = modal_analysis(md.frame);
  md.nominal_modal = modal_analysis(build_frame<N>(undamaged(p.frame)));
  md.loop = p.loop;
  md.h = 1.0 / p.loop.sensor_rate_hz;
  md.period = static_cast<S>(md.h);
  md.divergence_limit = static_cast<S>(p.loop.divergence_limit_m);
  md.contact_rtol = std::fmax(static_cast<S>(p.loop.contact_rtol), S(64) * std::numeric_limits<S>::epsilon());
  md.floor = p.device.floor > 0 ? p.device.floor - 1 : N - 1;

  // Rayleigh damping fitted on two modes, zeta(w) = a0 / (2w) + a1 w / 2, goes
  // negative on the other modes when a1 < 0 or a0 < 0: they would grow
  // without bound, so the frame is refused (beyond rounding).
  for (int j = 0; j < N; ++j)
    if (p.frame.damping == DampingRule::kRayleigh && md.modal.zeta(j) < -1e-9)
      return {"frame.rayleigh_zeta",
              "gives another mode a negative damping ratio (its response would grow without "
              "bound): zeta2 / zeta1 must lie between w1 / w2 and w2 / w1 of the two modes"};

  // Classical damping is what makes the modal blocks exact: check it.
  if constexpr (Model<S, N, Dev>::kModal) {
    const Eigen::Matrix<double, N, N> cm = md.modal.phi.transpose() * md.frame.C * md.modal.phi;
    const double diag = cm.diagonal().cwiseAbs().maxCoeff();
    if ((cm - Eigen::Matrix<double, N, N>(cm.diagonal().asDiagonal())).cwiseAbs().maxCoeff() >
        1e-8 * (diag > 0.0 ? diag : 1.0))
      return {"frame.damping", "is not classical (modal coordinates would not decouple)"};
  }
  return {};
}

// 3. The linear part: the TMD adds a degree of freedom to the physical
// frame (dense form); otherwise the frame in modal coordinates, padded
// modes j >= N inert (no coupling, no input, zero rows: they stay 0).
template <typename S, int N, typename Dev, int NX, int P>
void linear_part(const SceneParams& p, double device_mass, Model<S, N, Dev>& md, LinearPart<NX, P>& lp) {
  lp.m.setZero();
  lp.k_frame.setZero();
  lp.k_device.setZero();
  lp.c.setZero();
  lp.m.template topLeftCorner<N, N>() = md.frame.m.asDiagonal();
  lp.k_frame.template topLeftCorner<N, N>() = md.frame.K;
  lp.c.template topLeftCorner<N, N>() = md.frame.C;
  LtiSpec<NX>& spec = lp.spec;
  spec.a.setZero();
  spec.bg.setZero();
  spec.bf.setZero();
  lp.px.setZero();
  lp.pv.setZero();
  md.pos_map.setZero();
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    const TmdDesign t = design_tmd(p.device.tmd, device_mass, md.nominal_modal.m_eff(0), md.nominal_modal.omega(0));
    md.dev.design = t;
    const int f = md.floor, d = N;
    lp.m(d, d) = t.mass;
    lp.k_device(f, f) = lp.k_device(d, d) = t.k;
    lp.k_device(f, d) = lp.k_device(d, f) = -t.k;
    lp.c(f, f) += t.c;
    lp.c(d, d) += t.c;
    lp.c(f, d) -= t.c;
    lp.c(d, f) -= t.c;
    const Eigen::Matrix<double, P, P> minv = lp.m.diagonal().cwiseInverse().asDiagonal();
    spec.a.template topRightCorner<P, P>().setIdentity();
    spec.a.template bottomLeftCorner<P, P>() = -minv * (lp.k_frame + lp.k_device);
    spec.a.template bottomRightCorner<P, P>() = -minv * lp.c;
    spec.bg.template tail<P>().setConstant(-1.0);
    lp.px.template leftCols<P>().setIdentity();
    lp.pv.template rightCols<P>().setIdentity();
    md.pos_map.template leftCols<N>().setIdentity();
  } else {
    (void)p;
    (void)device_mass;
    const Modal<N>& mo = md.modal;
    for (int j = 0; j < N; ++j) {
      const double w = mo.omega(j);
      spec.a(j, P + j) = 1.0;
      spec.a(P + j, j) = -w * w;
      spec.a(P + j, P + j) = -2.0 * mo.zeta(j) * w;
      spec.bg(P + j) = -mo.gamma(j);
      spec.bf(P + j) = mo.phi(md.floor, j);
      lp.px.col(j).template head<N>() = mo.phi.col(j);
      lp.pv.col(P + j).template head<N>() = mo.phi.col(j);
    }
    md.pos_map.template leftCols<N>() = mo.phi.template cast<S>();
  }
}

// 4. The exact step, the rows of the top floor, the device floor and the
// floor bound, the top floor's acceleration row, the floors' accelerations.
template <typename S, int N, typename Dev, int NX, int P>
void discretise(const LinearPart<NX, P>& lp, Model<S, N, Dev>& md) {
  md.rows.top = md.pos_map.row(N - 1).transpose();
  md.rows.dev = md.pos_map.row(md.floor).transpose();
  md.rows.bound = md.pos_map.cwiseAbs().colwise().maxCoeff().transpose();
  md.rows.dev_is_top = md.floor == N - 1;
  if constexpr (Model<S, N, Dev>::kModal) md.lti = discretise_modal<S, P>(lp.spec, md.h);
  else md.lti = discretise_dense<S, NX>(lp.spec, md.h);
  md.top_acc_z = lp.pv.row(N - 1).lazyProduct(lp.spec.a).transpose().template cast<S>();
  md.top_acc_ag = static_cast<S>(lp.pv.row(N - 1).dot(lp.spec.bg));
  const Eigen::Matrix<double, N, 1> minv_frame = md.frame.m.cwiseInverse();
  md.minv_k = (minv_frame.asDiagonal() * md.frame.K).template cast<S>();
  md.minv_c = (minv_frame.asDiagonal() * md.frame.C).template cast<S>();
  md.inv_floor_mass = static_cast<S>(1.0 / md.frame.m(md.floor));
}

// 5. Energies and powers as quadratic forms in [z; a_g], and the exact step
// integrals: E_e always, the ledger's input and damping when asked for.
template <typename S, int N, typename Dev, int NX, int P>
void energy_forms(const LinearPart<NX, P>& lp, Model<S, N, Dev>& md) {
  using M = Model<S, N, Dev>;
  using QX = Eigen::Matrix<double, NX, NX>;
  const auto& px = lp.px;
  const auto& pv = lp.pv;
  const auto q_kin = zz_form<NX>(QX(0.5 * pv.transpose() * lp.m * pv));
  const auto q_strain = zz_form<NX>(QX(0.5 * px.transpose() * lp.k_frame * px));
  const auto q_devpot = zz_form<NX>(QX(0.5 * px.transpose() * lp.k_device * px));
  const auto q_damp = zz_form<NX>(QX(pv.transpose() * lp.c * pv));
  // Input power -a_g (sum of m v) as a bilinear form: off-diagonal halves.
  Eigen::Matrix<double, NX + 1, NX + 1> q_in = Eigen::Matrix<double, NX + 1, NX + 1>::Zero();
  const Eigen::Matrix<double, NX, 1> mv = pv.transpose().lazyProduct(lp.m.diagonal());
  q_in.template block<NX, 1>(0, NX) = -0.5 * mv;
  q_in.template block<1, NX>(NX, 0) = -0.5 * mv.transpose();

  auto form = [](const auto& q) {
    if constexpr (M::kModal) return form_modal<S, P>(q);
    else return form_dense<S, NX>(q);
  };
  auto integral = [&](const auto& q) {
    if constexpr (M::kModal) return quad_integral_modal<S, P>(lp.spec, q, md.h);
    else return quad_integral_dense<S, NX>(lp.spec, q, md.h);
  };
  md.kinetic = form(q_kin);
  md.strain = form(q_strain);
  md.device_potential = form(q_devpot);
  md.damping_power = form(q_damp);
  md.input_power = form(q_in);
  md.strain_step = integral(q_strain);
  if constexpr (M::kModal)
    md.ee_lyapunov = lyapunov_split<S, P>(lp.spec, q_strain, md.h, &md.rows, &md.ee_boundary);
  if (md.loop.energy_ledger) {
    md.input_step = integral(q_in);
    md.damping_step = integral(q_damp);
  }
}

// 6. The VI NES: its design (the law's step, contact_laws.hpp), constants
// in S, the sub-stepper's scales and the exact free flight's coefficients.
template <typename S, int N, typename Dev>
ParamError build_vines(const VinesParams& vp, double device_mass, Model<S, N, Dev>& md) {
  const VinesDesign d = design_vines(vp, device_mass, md.frame.m(md.floor));
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
  dm.radius = static_cast<S>(d.radius);
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
  dm.count_depth = static_cast<S>(std::fmax(md.loop.contact_count_depth_m, resolution));
  return {};
}

}  // namespace detail

// Builds the model in place (it can be large: keep it static). Returns the
// first problem found; the model is usable only when the result is ok().
template <typename S, int N, typename Dev>
ParamError build_model(const SceneParams& p, Model<S, N, Dev>* out) {
  using M = Model<S, N, Dev>;
  Model<S, N, Dev>& md = *out;
  ParamError err = validate(p);
  if (err.ok()) err = detail::check_compiled<S, N, Dev>(p);
  if (err.ok()) err = detail::build_frames(p, md);
  if (!err.ok()) return err;
  const double device_mass =
      p.device.mass_kg > 0.0 ? p.device.mass_kg : p.device.mass_ratio * md.nominal_modal.m_eff(0);

  detail::LinearPart<M::kNx, M::kP> lp;
  detail::linear_part(p, device_mass, md, lp);
  detail::discretise(lp, md);
  detail::energy_forms(lp, md);
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    err = detail::build_vines(p.device.vines, device_mass, md);
    if (!err.ok()) return err;
  }
  return set_initial_conditions(p.device, out);
}

}  // namespace vines
#endif  // VINES_MODEL_REPORT
