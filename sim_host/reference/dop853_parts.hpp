// The tuned DOP853's pieces (dop853_tuned.cpp): its tableau as compile-time
// constants, a scalar along an accepted step's dense output, a root of it,
// and the bound of a cubic Hermite interpolant's departure from its chord.
#pragma once

#include <algorithm>
#include <cmath>

#include "sim_host/reference/dop853.hpp"

namespace vines::host::reference::tuned {

// The extended tableau in double: rows 0..11 the stages, 12 the 8th-order
// weights (its stage is f at the step's end), 13..15 the dense output's.
constexpr double tableau(int i, int j) {
  if (i >= 13) return static_cast<double>(Dop853Dense::a[i - 13][j]);
  return j < Dop853Table::kStages ? static_cast<double>(Dop853Table::a[i][j]) : 0.0;
}
constexpr double node(int i) {
  return i < 12 ? static_cast<double>(Dop853Table::c[i]) : i == 12 ? 1.0 : static_cast<double>(Dop853Dense::c[i - 13]);
}
constexpr int nonzeros(int i) {
  int n = 0;
  for (int j = 0; j < i; ++j) n += tableau(i, j) != 0.0;
  return n;
}
template <int I, int J>
constexpr double kA = tableau(I, J);
template <int J>
constexpr double kE5 = static_cast<double>(Dop853Table::e5[J]);
template <int J>
constexpr double kE3 = static_cast<double>(Dop853Table::e3[J]);
template <int R, int J>
constexpr double kD = static_cast<double>(Dop853Dense::d[R][J]);

// A scalar along an accepted step's dense output, theta in [0, 1], in
// Hairer's form: p = c0 + th (c1 + (1-th) (c2 + th (c3 + (1-th) (c4 + th (c5
// + (1-th) (c6 + th c7)))))).
struct Poly {
  double c[8];
  double at(double th) const {
    const double u = 1.0 - th;
    return c[0] + th * (c[1] + u * (c[2] + th * (c[3] + u * (c[4] + th * (c[5] + u * (c[6] + th * c[7]))))));
  }
  // dp/dtheta, from the inside out.
  double slope(double th) const {
    const double u = 1.0 - th;
    double q = c[6] + th * c[7], dq = c[7];
    dq = -q + u * dq, q = c[5] + u * q;
    dq = q + th * dq, q = c[4] + th * q;
    dq = -q + u * dq, q = c[3] + u * q;
    dq = q + th * dq, q = c[2] + th * q;
    dq = -q + u * dq, q = c[1] + u * q;
    return q + th * dq;
  }
};

// A root of p in (lo, hi]: sign * p <= 0 at lo, > 0 at hi, narrowed by
// Illinois (bisecting when the secant leaves the bracket or stalls) to tol.
struct Root {
  double lo, hi;
};
Root locate(const Poly& p, double lo, double hi, double sign, double tol) {
  double glo = sign * p.at(lo), ghi = sign * p.at(hi), width = hi - lo;
  int last = 0;
  for (int it = 0; it < 300 && hi - lo > tol; ++it) {
    double x = (lo * ghi - hi * glo) / (ghi - glo);
    const bool stalled = it % 4 == 3 && hi - lo > 0.5 * width;
    if (it % 4 == 3) width = hi - lo;
    if (!(x > lo && x < hi) || stalled) x = 0.5 * (lo + hi);
    const double gx = sign * p.at(x);
    if (gx > 0.0) {
      hi = x, ghi = gx;
      if (last == 1) glo *= 0.5;
      last = 1;
    } else {
      lo = x, glo = gx;
      if (last == -1) ghi *= 0.5;
      last = -1;
    }
  }
  return {lo, hi};
}

// How far the cubic Hermite interpolant on [0, len] (values g0, g1, slopes
// d0, d1) can stray from its chord: a quarter of the largest departure of
// the end slopes from the chord's. Skips the stationary points when no
// hidden root is possible.
double hermite_bulge(double g0, double d0, double g1, double d1, double len) {
  const double chord = g1 - g0;
  return 0.25 * std::max(std::fabs(d0 * len - chord), std::fabs(d1 * len - chord));
}

}  // namespace vines::host::reference::tuned
