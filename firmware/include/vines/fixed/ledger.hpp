// The energy ledger in fixed point (issue 34, docs/fixed_point.md), for the
// modal frame (the bare frame, the VI NES): the double ledger's balance
// (data.hpp: initial + input = stored + dissipated) in 64-bit sums with 40
// fractional bits of a unit E_L of their own.
//
// Over a sensor step each mode's speed, and the particle's, is the cubic
// Hermite interpolant of its ends (the speed and h times the acceleration
// there, the contact force included), as the double split scheme's
// quadrature takes it (substep_split.hpp); its integrals are exact:
//   int_0^1 v^2 dtau = x^T G x,  int_0^1 a v dtau = a0 B0 x + a1 B1 x,
// x = [v0, h v0', v1, h v1'] in the mode's unit, a the ground acceleration
// linear over the step. Damping work c_j h int v^2, input work
// -a (sum_j L_j v_j + m s') from them; stored energies at the step's end
// from the squares of the state; the contacts' loss is the split step's own
// (fixed/vines_step.hpp, FixedVinesData::lost). Each square and product of
// two Fixed is exact in 64 bits (56 fractional bits) and takes its unit's
// factor once (numeric::wide_times), rounded to 2^-40 E_L: a step's work is
// then resolved to ~1e-12 of the frame's energy scale, whatever its size.
// Work: a few dozen products per mode, only when loop.energy_ledger asks.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/fixed_gain.hpp"
#include "vines/numeric/fixed_math.hpp"

namespace vines::fixed {

// The accumulators' format: E_L with 40 fractional bits (range +-2^23 E_L).
inline constexpr int kLedgerBits = 40;
// A product of two Q3.28 has 56 fractional bits: its factors carry 2^-16.
inline constexpr int kSquareShift = -16;

template <int P>
struct FixedLedger {
  using G = numeric::Gain;
  using GainP = std::array<G, P>;
  bool on = false;  // loop.energy_ledger: off, the step keeps none
  double unit = 0;  // E_L [J]
  // h q_j'' in the mode's velocity unit, from q, q', a_g and the device's
  // force on its floor [F_u].
  GainP dq, dv, da, df;
  // Per square of a mode's coordinate, or int v^2 / int a v, in E_L 2^-16.
  GainP kinetic, strain, damping, input;
  // The particle (VI NES): h s'' in Vp from a_g and its contact force
  // [F_u]; its kinetic energy and input work per square in E_L 2^-16; the
  // contacts' energy unit m V^2 in E_L, and the elastic part's potential
  // (2/5) F delta per product F delta [F_u D].
  G p_da, p_df, p_kinetic, p_input, contact, potential;
};

struct FixedLedgerData {
  using W = numeric::Wide<kLedgerBits>;
  W initial, input, damping;  // summed over the run
  W kinetic, strain, device, contact, residual;  // at the last step's end
  W max_abs_residual, max_input;

  // In the host's double ledger (data.hpp) [J].
  Ledger read(double unit) const {
    Ledger l;
    l.initial = static_cast<double>(initial) * unit;
    l.input = static_cast<double>(input) * unit;
    l.damping = static_cast<double>(damping) * unit;
    l.contact = static_cast<double>(contact) * unit;
    l.kinetic = static_cast<double>(kinetic) * unit;
    l.strain = static_cast<double>(strain) * unit;
    l.device = static_cast<double>(device) * unit;
    l.residual = static_cast<double>(residual) * unit;
    l.max_abs_residual = static_cast<double>(max_abs_residual) * unit;
    l.max_input = static_cast<double>(max_input) * unit;
    return l;
  }
};

namespace detail {

// The Hermite basis' integrals on [0, 1] (the Gram matrix G, 1/420 its
// unit; B0, B1 against 1 - tau and tau, 1/60), as Q3.28 raw values.
constexpr std::int32_t ratio_raw(int num, int den) {
  const std::int64_t one = std::int64_t{1} << 28, n = num * one;
  return static_cast<std::int32_t>(n >= 0 ? (n + den / 2) / den : -((-n + den / 2) / den));
}
inline constexpr std::int32_t kGram[4][4] = {
    {ratio_raw(156, 420), ratio_raw(22, 420), ratio_raw(54, 420), ratio_raw(-13, 420)},
    {ratio_raw(22, 420), ratio_raw(4, 420), ratio_raw(13, 420), ratio_raw(-3, 420)},
    {ratio_raw(54, 420), ratio_raw(13, 420), ratio_raw(156, 420), ratio_raw(-22, 420)},
    {ratio_raw(-13, 420), ratio_raw(-3, 420), ratio_raw(-22, 420), ratio_raw(4, 420)}};
inline constexpr std::int32_t kRamp[2][4] = {{ratio_raw(21, 60), ratio_raw(3, 60), ratio_raw(9, 60), ratio_raw(-2, 60)},
                                             {ratio_raw(9, 60), ratio_raw(2, 60), ratio_raw(21, 60), ratio_raw(-3, 60)}};

template <typename Q>
std::int64_t square(Q x) {
  return std::int64_t{x.raw()} * x.raw();
}

// sum_k c[k] x[k] (c: Q3.28 raw constants), one rounding.
template <typename Q>
Q dot4(const std::int32_t* c, const Q* x) {
  std::int64_t s = 0;
  for (int k = 0; k < 4; ++k) s += std::int64_t{c[k]} * x[k].raw();
  return Q::saturated((s + (std::int64_t{1} << (Q::kFractionBits - 1))) >> Q::kFractionBits);
}

// int_0^1 a v dtau for the Hermite speed x, a from a0 to a1 [56 bits].
template <typename Q>
std::int64_t ramp_integral(const Q* x, Q a0, Q a1) {
  return std::int64_t{a0.raw()} * dot4(kRamp[0], x).raw() + std::int64_t{a1.raw()} * dot4(kRamp[1], x).raw();
}

// int_0^1 v^2 dtau for the Hermite speed x [56 bits].
template <typename Q>
std::int64_t square_integral(const Q* x) {
  std::int64_t s = 0;
  for (int a = 0; a < 4; ++a) s += std::int64_t{x[a].raw()} * dot4(kGram[a], x).raw();
  return s;
}

inline numeric::Wide<kLedgerBits> scaled(std::int64_t raw, numeric::Gain g) {
  return numeric::Wide<kLedgerBits>::from_raw(wide_times(raw, g));
}

}  // namespace detail

// One sensor step of the modes from z0 to z1 (Z: the 2P state [q; q'] in
// the modes' units) under a_g from a0 to a1 [sa] and the device's force on
// its floor f0, f1 at the ends [F_u]: the damping and input work.
template <int P, typename Q, typename Z>
void ledger_modes_step(const FixedLedger<P>& l, FixedLedgerData& d, const Z& z0, const Z& z1, Q a0, Q a1, Q f0,
                       Q f1) {
  using W = numeric::Wide<Q::kFractionBits>;
  auto h_accel = [&](const Z& z, int j, Q a, Q f) {  // h q_j'' in the mode's velocity unit
    const std::size_t i = static_cast<std::size_t>(j);
    W s = W::from_raw(wide_product(z(j), l.dq[i]));
    s += W::from_raw(wide_product(z(P + j), l.dv[i]));
    s += W::from_raw(wide_product(a, l.da[i]));
    s += W::from_raw(wide_product(f, l.df[i]));
    return s.template to_fixed<Q::kFractionBits>();
  };
  for (int j = 0; j < P; ++j) {
    const std::size_t i = static_cast<std::size_t>(j);
    const Q x[4] = {z0(P + j), h_accel(z0, j, a0, f0), z1(P + j), h_accel(z1, j, a1, f1)};
    d.damping += detail::scaled(detail::square_integral(x), l.damping[i]);
    d.input += detail::scaled(detail::ramp_integral(x, a0, a1), l.input[i]);
  }
}

// The particle's input work over the step from speed sd0 to sd1 [Vp] under
// its contact force p0, p1 at the ends [F_u].
template <int P, typename Q>
void ledger_particle_step(const FixedLedger<P>& l, FixedLedgerData& d, Q sd0, Q sd1, Q a0, Q a1, Q p0, Q p1) {
  const Q x[4] = {sd0, a0 * l.p_da + p0 * l.p_df, sd1, a1 * l.p_da + p1 * l.p_df};
  d.input += detail::scaled(detail::ramp_integral(x, a0, a1), l.p_input);
}

// The stored energies at a step's end (the modes z, the particle's speed
// sd, the contact's elastic force and overlap [F_u, D]; 0 with none), the
// contacts' loss so far [m V^2] and the balance.
template <int P, typename Q, typename Z>
void ledger_close(const FixedLedger<P>& l, FixedLedgerData& d, const Z& z, Q sd, Q elastic, Q depth,
                  numeric::Wide<kLedgerBits> lost) {
  using W = numeric::Wide<kLedgerBits>;
  d.kinetic = detail::scaled(detail::square(sd), l.p_kinetic);
  d.strain = W::from_raw(0);
  for (int j = 0; j < P; ++j) {
    const std::size_t i = static_cast<std::size_t>(j);
    d.kinetic += detail::scaled(detail::square(z(P + j)), l.kinetic[i]);
    d.strain += detail::scaled(detail::square(z(j)), l.strain[i]);
  }
  d.device = detail::scaled(std::int64_t{elastic.raw()} * depth.raw(), l.potential);
  d.contact = detail::scaled(lost.raw(), l.contact);
  W in = d.initial;
  in += d.input;
  W out = d.kinetic;
  out += d.strain;
  out += d.device;
  out += d.damping;
  out += d.contact;
  d.residual = W::from_raw(in.raw() - out.raw());
  const std::int64_t r = d.residual.raw() < 0 ? -d.residual.raw() : d.residual.raw();
  if (r > d.max_abs_residual.raw()) d.max_abs_residual = W::from_raw(r);
  const std::int64_t most = in.raw() > out.raw() ? in.raw() : out.raw();
  if (most > d.max_input.raw()) d.max_input = W::from_raw(most);
}

// At t = 0: what the initial conditions store is put in.
template <int P, typename Q, typename Z>
void ledger_init(const FixedLedger<P>& l, FixedLedgerData& d, const Z& z, Q sd) {
  d = FixedLedgerData{};
  ledger_close(l, d, z, sd, Q(0), Q(0), numeric::Wide<kLedgerBits>{});
  d.initial = d.kinetic;
  d.initial += d.strain;
  ledger_close(l, d, z, sd, Q(0), Q(0), numeric::Wide<kLedgerBits>{});
  d.max_abs_residual = numeric::Wide<kLedgerBits>{};
}

#if VINES_MODEL_REPORT
// The units of the particle's part (VI NES): its mass [kg], speed unit Vp
// [m/s], the contact's force unit F_u [N] and energy unit m V^2 [J].
struct ParticleUnits {
  double mass = 0, speed = 0, force = 0, energy = 0;
};

// The ledger of the double model m (a modal frame) stepped in the modes'
// units sq_j, sv_j at the ground's unit sa; E_L is the modes' kinetic
// energy at their units, over 2^12 (the sums' range: 2^11 times it).
template <int P, int N, typename Dev>
FixedLedger<P> build_fixed_ledger(const Model<double, N, Dev>& m, const Eigen::Matrix<double, P, 1>& sq,
                                  const Eigen::Matrix<double, P, 1>& sv, double sa, const ParticleUnits& pu) {
  using G = numeric::Gain;
  const auto& l = m.lti;
  const double h = m.h, sq_unit = std::ldexp(1.0, kSquareShift);
  FixedLedger<P> o;
  o.on = m.loop.energy_ledger;
  o.unit = 0;
  for (int j = 0; j < P; ++j) o.unit += m.kinetic.vv(j) * sv(j) * sv(j);
  o.unit = std::ldexp(o.unit, -12);
  const double e = sq_unit / o.unit;
  for (int j = 0; j < P; ++j) {
    const std::size_t i = static_cast<std::size_t>(j);
    o.dq[i] = G(h * l.ak(j) * sq(j) / sv(j));
    o.dv[i] = G(h * l.ac(j));
    o.da[i] = G(h * l.bgv(j) * sa / sv(j));
    o.df[i] = G(pu.force > 0 ? h * l.bfv(j) * pu.force / sv(j) : 0.0);
    o.kinetic[i] = G(m.kinetic.vv(j) * sv(j) * sv(j) * e);
    o.strain[i] = G(m.strain.qq(j) * sq(j) * sq(j) * e);
    o.damping[i] = G(m.damping_power.vv(j) * sv(j) * sv(j) * h * e);
    o.input[i] = G(m.input_power.va(j) * sv(j) * sa * h * e);
  }
  if (pu.mass > 0) {
    o.p_da = G(-h * sa / pu.speed);
    o.p_df = G(h * pu.force / (pu.mass * pu.speed));
    o.p_kinetic = G(0.5 * pu.mass * pu.speed * pu.speed * e);
    o.p_input = G(-pu.mass * sa * pu.speed * h * e);
    o.contact = G(pu.energy / o.unit);
    o.potential = G(0.4 * pu.energy * e);
  }
  return o;
}
#endif

}  // namespace vines::fixed
