// Cubic and quintic Hermite interpolation on one step [0, h]: used to place
// events (contact start and end) and the peaks of a response inside a step
// from the values and derivatives at its two ends.
#pragma once

#include <cmath>

namespace vines::numeric {

// Cubic through (0, y0, y0') and (h, y1, y1'); theta = t / h in [0, 1].
template <typename S>
struct Cubic {
  S y0, d0, y1, d1, h;  // d = derivative times h

  static Cubic make(S y0, S dy0, S y1, S dy1, S h) { return {y0, dy0 * h, y1, dy1 * h, h}; }

  S value(S th) const {
    const S th2 = th * th, th3 = th2 * th;
    return (S(2) * th3 - S(3) * th2 + S(1)) * y0 + (th3 - S(2) * th2 + th) * d0 +
           (S(-2) * th3 + S(3) * th2) * y1 + (th3 - th2) * d1;
  }
  S slope(S th) const {  // d/dtheta
    const S th2 = th * th;
    return (S(6) * th2 - S(6) * th) * y0 + (S(3) * th2 - S(4) * th + S(1)) * d0 +
           (S(-6) * th2 + S(6) * th) * y1 + (S(3) * th2 - S(2) * th) * d1;
  }
  // Largest value on [0, 1] (ends and interior stationary points).
  S max_value() const {
    using std::fabs;  // and numeric's own for the fixed-point scalar
    using std::sqrt;
    S best = y0 > y1 ? y0 : y1;
    // slope = A th^2 + B th + C
    const S a = S(6) * y0 + S(3) * d0 - S(6) * y1 + S(3) * d1;
    const S b = S(-6) * y0 - S(4) * d0 + S(6) * y1 - S(2) * d1;
    const S c = d0;
    // Roots inside (0, 1) only, each found without dividing outside it (a
    // fixed-point quotient out of range would saturate for nothing).
    S roots[2];
    int n = 0;
    auto inside = [&](S num, S den) {
      if (den < S(0)) {
        num = -num;
        den = -den;
      }
      if (num > S(0) && num < den) roots[n++] = num / den;
    };
    if (fabs(a) > S(1e-30) * (fabs(b) + fabs(c))) {
      const S disc = b * b - S(4) * a * c;
      if (disc >= S(0)) {
        const S sq = sqrt(disc);
        inside(-b + sq, S(2) * a);
        inside(-b - sq, S(2) * a);
      }
    } else if (fabs(b) > S(0)) {
      inside(-c, b);
    }
    for (int i = 0; i < n; ++i) {
      const S v = value(roots[i]);
      if (v > best) best = v;
    }
    return best;
  }
  // First theta in (0, 1] where the cubic rises through zero, given
  // value(0) <= 0: bracketing on a fine grid, then `halvings` bisections
  // (60: to rounding; a caller that refines the root itself needs fewer).
  // Returns 1 if none is found (the caller re-checks with the true solution).
  S first_upcrossing(int halvings = 60) const;
};

// The first cell [*lo, *hi] of a 16-point grid on [0, 1] where the curve c
// (c.value(theta), f0 = its value at 0) rises through zero; false if none.
template <typename Curve, typename S>
bool grid_upcrossing(const Curve& c, S f0, S* lo, S* hi) {
  constexpr int kGrid = 16;
  S a = S(0), fa = f0;
  for (int i = 1; i <= kGrid; ++i) {
    const S b = a + S(1.0 / kGrid), fb = c.value(b);  // i / kGrid exactly (no S(16): past Q3.28)
    if (fb > S(0) && fa <= S(0)) {
      *lo = a;
      *hi = b;
      return true;
    }
    a = b;
    fa = fb;
  }
  return false;
}

// The first theta in (0, 1] where the curve c rises through zero (f0 =
// its value at 0 <= 0): the grid's cell, then `halvings` bisections; 1 if
// none.
template <typename Curve, typename S>
S upcrossing(const Curve& c, S f0, int halvings) {
  S a, b;
  if (!grid_upcrossing(c, f0, &a, &b)) return S(1);
  for (int it = 0; it < halvings; ++it) {
    const S m = S(0.5) * (a + b);
    if (c.value(m) > S(0)) b = m; else a = m;
  }
  return b;
}

template <typename S>
S Cubic<S>::first_upcrossing(int halvings) const {
  return upcrossing(*this, y0, halvings);
}

// The same cubic in powers of theta, c0 + c1 th + c2 th^2 + c3 th^3: three
// products a value against the Hermite form's twenty (the fixed-point
// step's 40 values of a contact start on a Cortex-M3).
template <typename S>
struct PowerCubic {
  S c0, c1, c2, c3;

  explicit PowerCubic(const Cubic<S>& c)
      : c0(c.y0),
        c1(c.d0),
        c2(S(3) * (c.y1 - c.y0) - S(2) * c.d0 - c.d1),
        c3(S(2) * (c.y0 - c.y1) + c.d0 + c.d1) {}
  S value(S th) const { return c0 + th * (c1 + th * (c2 + th * c3)); }
  S first_upcrossing(int halvings) const { return upcrossing(*this, c0, halvings); }
};

// The cubic Hermite interpolant of a vector function on [0, h] (values y0,
// y1 and derivatives f0, f1 at the ends) at theta = t / h (also outside [0, 1]).
template <typename Vec, typename S>
Vec hermite_point(const Vec& y0, const Vec& f0, const Vec& y1, const Vec& f1, S h, S th) {
  const S th2 = th * th, th3 = th2 * th;
  const S w0 = S(2) * th3 - S(3) * th2 + S(1), w1 = S(1) - w0;
  const S d0 = (th3 - S(2) * th2 + th) * h, d1 = (th3 - th2) * h;
  return w0 * y0 + w1 * y1 + d0 * f0 + d1 * f1;
}

// Largest |y| on [0, h] of the quintic through values, first and second
// derivatives at both ends (accurate to h^6 for smooth y).
template <typename S>
S quintic_abs_max(S y0, S v0, S a0, S y1, S v1, S a1, S h) {
  // Coefficients of p(theta) = sum c_i theta^i with derivatives scaled by h.
  const S d0 = v0 * h, d1 = v1 * h, s0 = a0 * h * h, s1 = a1 * h * h;
  const S c0 = y0, c1 = d0, c2 = S(0.5) * s0;
  const S c3 = S(10) * (y1 - y0) - S(6) * d0 - S(4) * d1 - S(1.5) * s0 + S(0.5) * s1;
  const S c4 = S(-15) * (y1 - y0) + S(8) * d0 + S(7) * d1 + S(1.5) * s0 - s1;
  const S c5 = S(6) * (y1 - y0) - S(3) * (d0 + d1) - S(0.5) * s0 + S(0.5) * s1;
  auto p = [&](S t) { return c0 + t * (c1 + t * (c2 + t * (c3 + t * (c4 + t * c5)))); };
  auto dp = [&](S t) {
    return c1 + t * (S(2) * c2 + t * (S(3) * c3 + t * (S(4) * c4 + t * S(5) * c5)));
  };
  S best = std::fabs(y0) > std::fabs(y1) ? std::fabs(y0) : std::fabs(y1);
  // Stationary points: sign changes of p' on a grid, then Newton.
  constexpr int kGrid = 8;
  S prev = dp(S(0)), t0 = S(0);
  for (int i = 1; i <= kGrid; ++i, t0 += S(1.0 / kGrid)) {
    const S t1 = t0 + S(1.0 / kGrid), cur = dp(t1);
    if ((prev < S(0)) != (cur < S(0))) {
      // Bisection on the sign of p' (50 halvings: below any scalar's resolution).
      S a = t0, b = t1;
      const bool rising_at_a = prev > S(0);
      for (int it = 0; it < 50; ++it) {
        const S m = S(0.5) * (a + b);
        if ((dp(m) > S(0)) == rising_at_a) a = m; else b = m;
      }
      const S t = S(0.5) * (a + b);
      const S v = std::fabs(p(t));
      if (v > best) best = v;
    }
    prev = cur;
  }
  return best;
}

}  // namespace vines::numeric
