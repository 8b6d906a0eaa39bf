// A device's whole fixed-point model (issue 34): its step (the bare frame's
// modes, fixed/frame.hpp; the TMD's blocks, fixed/tmd.hpp; the VI NES,
// fixed/vines_step.hpp), its readout (fixed/readout.hpp) and its initial
// conditions, one block of static data: what the host's fixed-point engine
// runs and what the fixed-point model image (fixed/image.hpp) carries to a
// board, so host and board step and read the same bits.
#pragma once

#include <cmath>
#include <cstdint>
#include <type_traits>

#include <Eigen/Core>

#include "vines/fixed/frame.hpp"
#include "vines/fixed/image.hpp"
#include "vines/fixed/readout.hpp"
#include "vines/fixed/tmd.hpp"
#include "vines/fixed/vines_step.hpp"
#include "vines/model/contact_mode.hpp"
#include "vines/numeric/fixed_math.hpp"

namespace vines::fixed {

// Q3.28, the format of every fixed-point value (docs/fixed_point.md).
inline constexpr int kFixedBits = 28;

// The step of a device in fixed point: its model M and data D, and what
// every device reads the same way: frame(m) (sa, ee_unit, top_length,
// top_speed) and frame(d) (z, a_prev, steps, peaks, E_e). The bare frame's
// here, the TMD's and the VI NES's below.
template <int N, typename Dev>
struct DeviceStep {
  using M = FixedFrame<kFixedBits, N>;
  using D = FixedFrameData<M>;
  static const M& frame(const M& m) { return m; }
  static const D& frame(const D& d) { return d; }
  static D& frame(D& d) { return d; }
  static void init(const M& m, D& d, typename M::Q /*x0*/, typename M::Q /*v0*/, typename M::Q a0) {
    fixed_frame_init(m, d, a0);
  }
  static void step(const M& m, D& d, typename M::Q a1) { fixed_frame_step(m, d, a1); }
};

template <int N>
struct DeviceStep<N, TmdDevice> {
  using M = FixedTmd<kFixedBits, N + 1>;
  using D = FixedFrameData<M>;
  static const M& frame(const M& m) { return m; }
  static const D& frame(const D& d) { return d; }
  static D& frame(D& d) { return d; }
  // x0, v0: the TMD's initial displacement and speed [Ld, Vd].
  static void init(const M& m, D& d, typename M::Q x0, typename M::Q v0, typename M::Q a0) {
    fixed_tmd_init(m, d, x0, v0, a0);
  }
  static void step(const M& m, D& d, typename M::Q a1) { fixed_tmd_step(m, d, a1); }
};

template <int N, ContactLaw L>
struct DeviceStep<N, VinesDevice<L>> {
  using M = FixedVines<kFixedBits, N, LawOf<L>::template Kernel, kFixedMoments>;
  using D = FixedVinesData<M>;
  static const typename M::Frame& frame(const M& m) { return m.frame; }
  static const FixedFrameData<typename M::Frame>& frame(const D& d) { return d.frame; }
  static FixedFrameData<typename M::Frame>& frame(D& d) { return d.frame; }
  // v0: the particle's initial speed [Vp].
  static void init(const M& m, D& d, typename M::Q /*x0*/, typename M::Q v0, typename M::Q a0) {
    fixed_vines_init(m, d, v0, a0);
  }
  static void step(const M& m, D& d, typename M::Q a1) { fixed_vines_step(m, d, a1); }
};

// A TMD keeps no fixed-point energy ledger (its state is not modal).
struct NoLedger {
  bool on = false;
  double unit = 0;
};

// The block: what the host builds (build_node_model, below), the image
// carries byte for byte and a board runs; its data is Step's D.
template <int N, typename Dev>
struct NodeModel {
  using Step = DeviceStep<N, Dev>;
  using M = typename Step::M;
  using D = typename Step::D;
  using Q = typename M::Q;
  static constexpr int kNx = 2 * M::kP;
  static constexpr bool kLedger = Dev::kKind != DeviceKind::kTmd;  // a modal frame's (fixed/ledger.hpp)

  M step;
  FixedReadout<N, kNx> read;
  std::conditional_t<kLedger, FixedLedger<M::kP>, NoLedger> ledger;
  double h = 0;          // the sensor step [s]
  int split_steps = 0;   // the scene's loop.split_steps the step was built with
  Q x0 = Q(0), v0 = Q(0);  // initial conditions: a TMD's displacement and speed, a particle's speed
  Q particle_y0 = Q(0);    // VI NES: where the particle starts, from the box's centre [L]
  double force_unit = 0;   // VI NES: the readout's unit of the contact force, m V^2 / D [N]
};

// The image's identity of this instance.
template <int N, typename Dev>
constexpr ImageKind image_kind() {
  ImageKind k;
  k.device = static_cast<std::uint8_t>(Dev::kKind);
  if constexpr (Dev::kKind == DeviceKind::kVines) k.law = static_cast<std::uint8_t>(Dev::kLaw);
  k.stories = static_cast<std::uint8_t>(N);
  k.bits = static_cast<std::uint8_t>(kFixedBits);
  k.moments = static_cast<std::uint8_t>(kFixedMoments);
  k.align = static_cast<std::uint8_t>(alignof(NodeModel<N, Dev>));
  k.body = static_cast<std::uint32_t>(sizeof(NodeModel<N, Dev>));
  return k;
}

// The ground samples [m/s^2] in the model's unit sa (one division, the
// same bits on the host and a board); a non-finite one is replaced by the
// last good one (0 before any) and counted, as the double loop does.
struct SampleHold {
  double last_good = 0;
  std::uint32_t held = 0;
  template <typename Q>
  Q take(double a, double sa) {
    if (std::isfinite(a)) last_good = a;
    else ++held;
    return Q(last_good / sa);
  }
};

// The VI NES's contact at the step's end: the law's force on the particle,
// positive to the right (the double model's contact_force), and its
// elastic part [F_u]; the overlap [D]. All 0 with none (or no VI NES).
template <typename Q>
struct ContactEnd {
  Q force = Q(0), elastic = Q(0), depth = Q(0);
};

template <int N, typename Dev>
ContactEnd<typename NodeModel<N, Dev>::Q> contact_end(const NodeModel<N, Dev>& nm,
                                                      const typename NodeModel<N, Dev>::D& d) {
  using Q = typename NodeModel<N, Dev>::Q;
  ContactEnd<Q> c;
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    constexpr int P = NodeModel<N, Dev>::M::kP;
    if (d.side == 0) return c;
    const auto& m = nm.step;
    const Q vf = gain_dot<Q>(m.dev_v, d.frame.z.template tail<P>());
    c.depth = d.overlap * m.to_overlap;
    const Q q = numeric::sqrt(numeric::sqrt(c.depth));
    const Q u = Q(d.side) * (d.sd - vf) * m.to_speed;
    const contact::Force<Q> f = m.law[0].regular(q, u);
    c.elastic = f.elastic;
    c.force = d.side > 0 ? -f.total() : f.total();
  }
  return c;
}

template <int N, typename Dev>
numeric::Fixed<kFixedBits> contact_force(const NodeModel<N, Dev>& nm, const typename NodeModel<N, Dev>::D& d) {
  return contact_end(nm, d).force;
}

// At rest (a TMD or the particle at its initial conditions) on the first
// sample a0; the energy ledger opened when the model keeps one.
template <int N, typename Dev>
void node_init(const NodeModel<N, Dev>& nm, typename NodeModel<N, Dev>::D& d, typename NodeModel<N, Dev>::Q a0) {
  using NM = NodeModel<N, Dev>;
  NM::Step::init(nm.step, d, nm.x0, nm.v0, a0);
  if constexpr (NM::kLedger) {
    if (!nm.ledger.on) return;
    auto& fd = NM::Step::frame(d);
    typename NM::Q sd(0);
    if constexpr (Dev::kKind == DeviceKind::kVines) sd = d.sd;
    ledger_init(nm.ledger, fd.ledger, fd.z, sd);
  }
}

// One sensor step to the sample a1; with the energy ledger, its work over
// the step (the modes' and the particle's, between the contact's forces at
// the step's ends) and the balance at its end.
template <int N, typename Dev>
void node_step(const NodeModel<N, Dev>& nm, typename NodeModel<N, Dev>::D& d, typename NodeModel<N, Dev>::Q a1) {
  using NM = NodeModel<N, Dev>;
  using Q = typename NM::Q;
  if constexpr (NM::kLedger) {
    if (nm.ledger.on) {
      auto& fd = NM::Step::frame(d);
      const auto z0 = fd.z;  // a copy: the step moves fd.z
      const Q a0 = fd.a_prev;
      const ContactEnd<Q> c0 = contact_end(nm, d);
      Q sd0(0);
      if constexpr (Dev::kKind == DeviceKind::kVines) sd0 = d.sd;
      NM::Step::step(nm.step, d, a1);
      const ContactEnd<Q> c1 = contact_end(nm, d);
      ledger_modes_step(nm.ledger, fd.ledger, z0, fd.z, a0, a1, -c0.force, -c1.force);
      Q sd1(0);
      numeric::Wide<kLedgerBits> lost;
      if constexpr (Dev::kKind == DeviceKind::kVines) {
        sd1 = d.sd;
        lost = d.lost;
        ledger_particle_step(nm.ledger, fd.ledger, sd0, sd1, a0, a1, c0.force, c1.force);
      }
      ledger_close(nm.ledger, fd.ledger, fd.z, sd1, c1.elastic, c1.depth, lost);
      return;
    }
  }
  NM::Step::step(nm.step, d, a1);
}

// What a node reports of its state, read as the board and the host both
// read it (the board's telemetry, the host engine's snapshot): the floors
// and the top floor's acceleration from the readout, E_e, and for a VI NES
// the particle, the contact force (on the particle, positive to the right)
// and the contact's mode; with the energy ledger, the energy the contacts
// dissipated.
template <int N>
struct NodeReading {
  double x[N] = {};
  double acc_top = 0, elastic_energy = 0, particle_x = 0, particle_v = 0, contact_force = 0, dissipated = 0;
  Mode mode = Mode::kFree;
};

template <int N, typename Dev>
NodeReading<N> read_node(const NodeModel<N, Dev>& nm, const typename NodeModel<N, Dev>::D& d) {
  using NM = NodeModel<N, Dev>;
  using Q = typename NM::Q;
  const auto& fd = NM::Step::frame(d);
  NodeReading<N> r;
  for (int i = 0; i < N; ++i) r.x[i] = floor_x(nm.read, fd.z, i);
  Q force = Q(0);
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    force = contact_force(nm, d);
    r.particle_x = static_cast<double>(nm.particle_y0 + d.s) * nm.step.length;
    r.particle_v = static_cast<double>(d.sd) * nm.step.speed;
    r.contact_force = static_cast<double>(force) * nm.force_unit;
    r.mode = d.side < 0 ? Mode::kContactLeft : d.side > 0 ? Mode::kContactRight : Mode::kFree;
  }
  r.acc_top = top_acceleration(nm.read, fd.z, force);
  r.elastic_energy = static_cast<double>(fd.ee) * NM::Step::frame(nm.step).ee_unit;
  if (nm.ledger.on) r.dissipated = static_cast<double>(fd.ledger.contact) * nm.ledger.unit;
  return r;
}

#if VINES_MODEL_REPORT
// The node model of the double model m and the scene's fixed-point scales.
template <int N, typename Dev>
void build_node_model(const Model<double, N, Dev>& m, const FixedParams& f, NodeModel<N, Dev>* out) {
  using NM = NodeModel<N, Dev>;
  using Q = typename NM::Q;
  constexpr int NX = NM::kNx;
  NM& nm = *out;
  nm.x0 = nm.v0 = nm.particle_y0 = Q(0);
  nm.force_unit = 0;
  nm.h = m.h;
  nm.split_steps = m.loop.split_steps;
  constexpr int DX = Model<double, N, Dev>::kNx, DP = Model<double, N, Dev>::kP;
  Eigen::Matrix<double, DX, NX> to_z = Eigen::Matrix<double, DX, NX>::Zero();
  double f_unit = 0;
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    nm.step = build_fixed_tmd<kFixedBits>(m, f.accel_mps2, f.amplification);
    to_z = nm.step.back;
    nm.x0 = Q(m.dev.x0 / nm.step.dev_length);
    nm.v0 = Q(m.dev.v0 / nm.step.dev_speed);
  } else {
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      nm.step = build_fixed_vines<kFixedBits, kFixedMoments, LawOf<Dev::kLaw>>(
          m, FixedScales{f.accel_mps2, f.amplification, f.contact_speed_mps});
      nm.v0 = Q(m.dev.v0 / nm.step.speed);
      nm.particle_y0 = Q(m.dev.y0 / nm.step.length);
      f_unit = nm.force_unit = nm.step.cu.u.force();
    } else {
      nm.step = build_fixed_frame<kFixedBits>(m, f.accel_mps2, f.amplification);
    }
    const auto& fr = NM::Step::frame(nm.step);
    constexpr int P = NM::M::kP;
    for (int j = 0; j < P; ++j) {  // the double model's modes, padded to DP
      to_z(j, j) = fr.sq(j);
      to_z(DP + j, P + j) = fr.sv(j);
    }
    ParticleUnits pu;
    if constexpr (Dev::kKind == DeviceKind::kVines) {
      const ContactUnits& u = nm.step.cu.u;
      pu = {u.m, nm.step.speed, u.force(), u.m * u.v * u.v};
    }
    nm.ledger = build_fixed_ledger<P>(m, fr.sq, fr.sv, fr.sa, pu);
  }
  nm.read = build_readout<N, Dev, NX>(m, to_z, f_unit);
}
#endif

}  // namespace vines::fixed
