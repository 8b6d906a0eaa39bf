// One Dormand-Prince 5(4) step (the pair behind ode45), for sub-stepping
// through contacts: fixed-size state, no heap, the derivative at the new point
// returned for reuse (first same as last), an embedded error estimate, and
// the stages that Hairer's continuous extension of order 4 needs (dense
// output: the state anywhere inside the step, dopri5_dense).
// Step-size control and event location are the caller's.
#pragma once

namespace vines::numeric {

template <typename Vec>
struct Dopri5Result {
  Vec y;    // solution at t + h (5th order)
  Vec f;    // derivative at (t + h, y)
  Vec err;  // difference between the 5th- and 4th-order solutions
  Vec k3, k4, k5, k6;  // stages 3 to 6, for dense output
};

namespace detail {
// dy = rhs(t, y), written in place where the right-hand side can
// (rhs(t, y, &dy)): the stages are kept in the result without a copy.
template <typename Rhs, typename S, typename Vec>
auto eval_into(const Rhs& rhs, S t, const Vec& y, Vec* dy, int) -> decltype(rhs(t, y, dy), void()) {
  rhs(t, y, dy);
}
template <typename Rhs, typename S, typename Vec>
void eval_into(const Rhs& rhs, S t, const Vec& y, Vec* dy, long) {
  *dy = rhs(t, y);
}
}  // namespace detail

// rhs(t, y) -> y' (or rhs(t, y, &y')). f0 is rhs(t, y0). kError = false: no error estimate
// (r.err left unset), for fixed-step use.
template <typename Vec, bool kError = true, typename Scalar, typename Rhs>
Dopri5Result<Vec> dopri5_step(const Rhs& rhs, Scalar t, const Vec& y0, const Vec& f0, Scalar h) {
  using S = Scalar;
  constexpr S a21 = S(1.0 / 5.0);
  constexpr S a31 = S(3.0 / 40.0), a32 = S(9.0 / 40.0);
  constexpr S a41 = S(44.0 / 45.0), a42 = S(-56.0 / 15.0), a43 = S(32.0 / 9.0);
  constexpr S a51 = S(19372.0 / 6561.0), a52 = S(-25360.0 / 2187.0), a53 = S(64448.0 / 6561.0),
              a54 = S(-212.0 / 729.0);
  constexpr S a61 = S(9017.0 / 3168.0), a62 = S(-355.0 / 33.0), a63 = S(46732.0 / 5247.0),
              a64 = S(49.0 / 176.0), a65 = S(-5103.0 / 18656.0);
  constexpr S b1 = S(35.0 / 384.0), b3 = S(500.0 / 1113.0), b4 = S(125.0 / 192.0),
              b5 = S(-2187.0 / 6784.0), b6 = S(11.0 / 84.0);
  constexpr S e1 = S(71.0 / 57600.0), e3 = S(-71.0 / 16695.0), e4 = S(71.0 / 1920.0),
              e5 = S(-17253.0 / 339200.0), e6 = S(22.0 / 525.0), e7 = S(-1.0 / 40.0);

  Dopri5Result<Vec> r;
  Vec k2;
  detail::eval_into(rhs, t + S(0.2) * h, Vec(y0 + h * (a21 * f0)), &k2, 0);
  detail::eval_into(rhs, t + S(0.3) * h, Vec(y0 + h * (a31 * f0 + a32 * k2)), &r.k3, 0);
  detail::eval_into(rhs, t + S(0.8) * h, Vec(y0 + h * (a41 * f0 + a42 * k2 + a43 * r.k3)), &r.k4, 0);
  detail::eval_into(rhs, t + S(8.0 / 9.0) * h, Vec(y0 + h * (a51 * f0 + a52 * k2 + a53 * r.k3 + a54 * r.k4)), &r.k5, 0);
  detail::eval_into(rhs, t + h, Vec(y0 + h * (a61 * f0 + a62 * k2 + a63 * r.k3 + a64 * r.k4 + a65 * r.k5)), &r.k6, 0);
  r.y = y0 + h * (b1 * f0 + b3 * r.k3 + b4 * r.k4 + b5 * r.k5 + b6 * r.k6);
  detail::eval_into(rhs, t + h, r.y, &r.f, 0);
  if constexpr (kError) r.err = h * (e1 * f0 + e3 * r.k3 + e4 * r.k4 + e5 * r.k5 + e6 * r.k6 + e7 * r.f);
  return r;
}

// The continuous extension of a step (Hairer, Norsett, Wanner, "Solving
// ODEs I", II.6; dopri5.f's CONTD5): the state at theta h into the step,
// y0 + th (c1 + (1 - th) (c2 + th (c3 + (1 - th) c4))), of order 4.
template <typename Vec>
struct Dopri5Dense {
  Vec y0, c1, c2, c3, c4;

  template <typename S>
  Vec at(S th) const {
    const S th1 = S(1) - th;
    return y0 + th * (c1 + th1 * (c2 + th * (c3 + th1 * c4)));
  }
};

// The dense output of the step r from (y0, f0) of length h.
template <typename Vec, typename Scalar>
Dopri5Dense<Vec> dopri5_dense(const Dopri5Result<Vec>& r, const Vec& y0, const Vec& f0, Scalar h) {
  using S = Scalar;
  constexpr S d1 = S(-12715105075.0 / 11282082432.0), d3 = S(87487479700.0 / 32700410799.0),
              d4 = S(-10690763975.0 / 1880347072.0), d5 = S(701980252875.0 / 199316789632.0),
              d6 = S(-1453857185.0 / 822651844.0), d7 = S(69997945.0 / 29380423.0);
  Dopri5Dense<Vec> o;
  o.y0 = y0;
  o.c1 = r.y - y0;
  o.c2 = h * f0 - o.c1;
  o.c3 = o.c1 - h * r.f - o.c2;
  o.c4 = h * (d1 * f0 + d3 * r.k3 + d4 * r.k4 + d5 * r.k5 + d6 * r.k6 + d7 * r.f);
  return o;
}

}  // namespace vines::numeric
