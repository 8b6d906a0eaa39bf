// One Dormand-Prince 5(4) step (the pair behind ode45), for sub-stepping
// through contacts: fixed-size state, no heap, the derivative at the new point
// returned for reuse (first same as last), and an embedded error estimate.
// Step-size control and event location are the caller's.
#pragma once

namespace vines::numeric {

template <typename Vec>
struct Dopri5Result {
  Vec y;    // solution at t + h (5th order)
  Vec f;    // derivative at (t + h, y)
  Vec err;  // difference between the 5th- and 4th-order solutions
};

// rhs(t, y) -> y'. f0 is rhs(t, y0). kError = false: no error estimate
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

  const Vec k2 = rhs(t + S(0.2) * h, Vec(y0 + h * (a21 * f0)));
  const Vec k3 = rhs(t + S(0.3) * h, Vec(y0 + h * (a31 * f0 + a32 * k2)));
  const Vec k4 = rhs(t + S(0.8) * h, Vec(y0 + h * (a41 * f0 + a42 * k2 + a43 * k3)));
  const Vec k5 = rhs(t + S(8.0 / 9.0) * h,
                     Vec(y0 + h * (a51 * f0 + a52 * k2 + a53 * k3 + a54 * k4)));
  const Vec k6 = rhs(t + h, Vec(y0 + h * (a61 * f0 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5)));
  Dopri5Result<Vec> r;
  r.y = y0 + h * (b1 * f0 + b3 * k3 + b4 * k4 + b5 * k5 + b6 * k6);
  r.f = rhs(t + h, r.y);
  if constexpr (kError) r.err = h * (e1 * f0 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * r.f);
  return r;
}

}  // namespace vines::numeric
