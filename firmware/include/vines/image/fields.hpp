// The body of a model image: one list of its fields (visit_fields), read
// by the writer, the loader and the sizes alike, and the body's shape (size,
// field count, layout check) computed from it at compile time.
#pragma once

#include <cstddef>
#include <cstdint>

#include "vines/image/codec.hpp"
#include "vines/model/model.hpp"

namespace vines::image {

// ---- the body: one list of fields for the writer, the loader and the sizes

// Calls v(part, &Model::a, &A::b, ...) for every field of the body, in
// order; the visitor applies the chain of member pointers to its model (the
// counting visitor to none: sizes come from the types, so image_bytes() is
// a constant).
template <typename S, int N, typename Dev, typename V>
constexpr void visit_fields(V& v) {
  using M = Model<S, N, Dev>;
  using L = typename M::LtiT;
  using Q = typename M::QuadT;
  using F = typename M::FormT;
  using Rows = ModalRows<S, M::kP>;
  using Boundary = ModalForm<S, M::kP>;
  using DM = DeviceModel<S, Dev>;
  constexpr int P = M::kP;
  constexpr int R = M::kModal ? N : P;  // real modes (modal), every coordinate (dense)
  constexpr Part all{1, -1, -1};
  constexpr Part modes{1, R, P};        // a vector over the position coordinates
  constexpr Part halves{2, R, P};       // a state vector [positions; velocities]
  constexpr Part floor_map{1, N * R, N * P};  // N x P, column by column

  // Loop settings, field by field.
  v(all, &M::loop, &LoopParams::sensor_rate_hz);
  v(all, &M::loop, &LoopParams::contact_rtol);
  v(all, &M::loop, &LoopParams::max_substeps_per_step);
  v(all, &M::loop, &LoopParams::contact_count_depth_m);
  v(all, &M::loop, &LoopParams::energy_ledger);
  v(all, &M::loop, &LoopParams::floor_peaks);
  v(all, &M::loop, &LoopParams::divergence_limit_m);
  v(all, &M::loop, &LoopParams::contact_scheme);
  v(all, &M::loop, &LoopParams::bounded_substeps);
  v(all, &M::loop, &LoopParams::split_steps);
  // New LoopParams fields here, one line each:
  //   v(all, &M::loop, &LoopParams::new_field);
  // Tripwire: a field added at the end of LoopParams without its line here
  // stops the build (then name the new last field below).
  constexpr std::size_t kLoopEnd = offsetof(LoopParams, split_steps) + sizeof(int);
  constexpr std::size_t kAlign = alignof(LoopParams);
  static_assert(sizeof(LoopParams) == (kLoopEnd + kAlign - 1) / kAlign * kAlign,
                "LoopParams has a field after split_steps: add its line to visit_fields");

  v(all, &M::h);
  v(all, &M::floor);
  v(all, &M::period);
  v(all, &M::divergence_limit);
  v(all, &M::contact_rtol);

  // Exact step of the linear part.
  if constexpr (M::kModal) {
    for (auto f : {&L::p11, &L::p12, &L::p21, &L::p22, &L::gx0, &L::gx1, &L::gv0, &L::gv1, &L::ak, &L::ac, &L::bgv,
                   &L::bfv})
      v(modes, &M::lti, f);
  } else {
    v(all, &M::lti, &L::phi);
    for (auto f : {&L::g0, &L::g1}) v(all, &M::lti, f);
  }
  // Step integrals (E_e, input work, damping) and instantaneous forms.
  for (auto q : {&M::strain_step, &M::input_step, &M::damping_step}) {
    if constexpr (M::kModal) {
      for (auto f : {&Q::qq, &Q::qv, &Q::vv, &Q::q0, &Q::q1, &Q::v0, &Q::v1}) v(modes, q, f);
      for (auto f : {&Q::c00, &Q::c01, &Q::c11}) v(all, q, f);
    } else {
      v(all, q, &Q::w);
    }
  }
  for (auto q : {&M::kinetic, &M::strain, &M::device_potential, &M::damping_power, &M::input_power}) {
    if constexpr (M::kModal) {
      for (auto f : {&F::qq, &F::qv, &F::vv, &F::qa, &F::va}) v(modes, q, f);
      v(all, q, &F::aa);
      v(all, q, &F::positions_only);
    } else {
      v(all, q, &F::q);
    }
  }
  // Readouts.
  v(floor_map, &M::pos_map);
  for (auto f : {&Rows::top, &Rows::dev, &Rows::bound, &Rows::lq0, &Rows::lq1, &Rows::lv0, &Rows::lv1})
    v(modes, &M::rows, f);
  for (auto f : {&Rows::l00, &Rows::l01, &Rows::l11}) v(all, &M::rows, f);
  v(all, &M::rows, &Rows::dev_is_top);
  v(all, &M::ee_lyapunov);
  for (auto f : {&Boundary::qq, &Boundary::qv, &Boundary::vv, &Boundary::qa, &Boundary::va})
    v(modes, &M::ee_boundary, f);
  v(all, &M::ee_boundary, &Boundary::aa);
  v(all, &M::ee_boundary, &Boundary::positions_only);
  v(halves, &M::top_acc_z);
  v(all, &M::top_acc_ag);
  v(all, &M::minv_k);
  v(all, &M::minv_c);
  v(all, &M::inv_floor_mass);

  // The device.
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    for (auto f : {&TmdDesign::mass, &TmdDesign::k, &TmdDesign::c, &TmdDesign::mu, &TmdDesign::lambda, &TmdDesign::xi,
                   &TmdDesign::omega})
      v(all, &M::dev, &DM::design, f);
    v(all, &M::dev, &DM::x0);
    v(all, &M::dev, &DM::v0);
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    using D = VinesDesign;
    using Law = decltype(DM::law);
    for (auto f : {&D::mass, &D::radius, &D::box_length, &D::gap, &D::c, &D::m_star, &D::eps, &D::tau, &D::v_ref, &D::g})
      v(all, &M::dev, &DM::design, f);
    v(all, &M::dev, &DM::design, &D::ok);
    for (auto f : {&DM::m, &DM::m_star, &DM::inv_m, &DM::wall_left, &DM::wall_right, &DM::y0, &DM::v0, &DM::c,
                   &DM::eps})
      v(all, &M::dev, f);
    // The law's coefficients, as its kernel lists them (contact_laws.hpp).
    Law::coefficients([&](auto coefficient) { v(all, &M::dev, &DM::law, coefficient); });
    for (auto f : {&DM::pos_scale, &DM::vel_scale, &DM::modal_scale, &DM::q_scale, &DM::w_step0, &DM::ff_a0,
                   &DM::ff_a1, &DM::ff_v, &DM::count_depth, &DM::event_tol, &DM::round_tol, &DM::clear_lo,
                   &DM::clear_hi, &DM::radius})
      v(all, &M::dev, f);
    // New DeviceModel fields of the VI NES here, one line each:
    //   v(all, &M::dev, &DM::new_field);
    // Tripwire, as for LoopParams (a field small enough to hide in the end
    // padding of one scalar shows in the other).
    static_assert(sizeof(DM) == (offsetof(DM, radius) + sizeof(S) + alignof(DM) - 1) / alignof(DM) * alignof(DM),
                  "DeviceModel (VI NES) has a field after radius: add its line to visit_fields");
  }
}

namespace detail {

// The body's size, field count and layout check (Counter over the list).
template <typename S, int N, typename Dev>
constexpr Shape shape() {
  Counter c;
  visit_fields<S, N, Dev>(c);
  return {c.bytes, c.fields, ~c.crc, c.fits};
}

}  // namespace detail

}  // namespace vines::image
