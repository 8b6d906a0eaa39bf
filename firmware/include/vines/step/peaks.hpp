// Running maxima of the response over a step, continuous in time: the peak
// inside a step is placed from the values and derivatives at its two ends.
#pragma once

#include <cmath>

#include "vines/model/data.hpp"
#include "vines/model/model.hpp"
#include "vines/numeric/hermite.hpp"
#include "vines/numeric/inline.hpp"
#include "vines/numeric/minmax.hpp"

namespace vines {

namespace detail {

// Running maxima over one step of |x| per floor and per story drift, from the
// values and velocities at both ends (cubic Hermite inside the step). Only
// steps that can beat the current maximum are refined.
template <typename S, int N>
void update_peaks(const Eigen::Matrix<S, N, 1>& x0, const Eigen::Matrix<S, N, 1>& v0,
                  const Eigen::Matrix<S, N, 1>& x1, const Eigen::Matrix<S, N, 1>& v1, S h,
                  Eigen::Matrix<S, N, 1>& peak_x, Eigen::Matrix<S, N, 1>& peak_drift) {
  auto refine = [h](S y0, S d0, S y1, S d1, S& peak) {
    const S ends = std::fabs(y0) > std::fabs(y1) ? std::fabs(y0) : std::fabs(y1);
    if (ends + S(0.5) * h * (std::fabs(d0) + std::fabs(d1)) <= peak) return;
    const auto c = numeric::Cubic<S>::make(y0, d0, y1, d1, h);
    const auto cn = numeric::Cubic<S>::make(-y0, -d0, -y1, -d1, h);
    const S a = c.max_value(), b = cn.max_value();
    const S m = a > b ? a : b;
    if (m > peak) peak = m;
  };
  for (int i = 0; i < N; ++i) {
    refine(x0(i), v0(i), x1(i), v1(i), peak_x(i));
    const S dx0 = i ? x0(i) - x0(i - 1) : x0(i), dx1 = i ? x1(i) - x1(i - 1) : x1(i);
    const S dv0 = i ? v0(i) - v0(i - 1) : v0(i), dv1 = i ? v1(i) - v1(i - 1) : v1(i);
    refine(dx0, dv0, dx1, dv1, peak_drift(i));
  }
}

// Bound on |x| over a step of length h from (x0, v0) to (x1, v1), from
// |x| and |v| at both ends: what a step must beat to be refined.
template <typename S>
VINES_INLINE S abs_bound(S ax0, S av0, S ax1, S av1, S h) {
  return numeric::max_of(ax0, ax1) + S(0.5) * h * (av0 + av1);
}
template <typename S>
VINES_INLINE S top_bound(S x0, S v0, S x1, S v1, S h) {
  return abs_bound(std::fabs(x0), std::fabs(v0), std::fabs(x1), std::fabs(v1), h);
}

// Peak of |top floor| over an exact step from (x0, v0) at z0 to (x1, v1) at
// z1 when the step can beat the running peak (by a cheap bound from both
// ends), else 0: quintic Hermite with the accelerations at both ends (error
// ~h^6), for a converged peak at any rate; the accelerations are a row of the
// model each (top_a), the quintic is the only call.
template <typename S, int N, typename Dev>
VINES_INLINE S top_peak_of_step(const Model<S, N, Dev>& m, const typename Model<S, N, Dev>::VecX& z0,
                                const typename Model<S, N, Dev>::VecX& z1, S a0, S a1, S x0, S v0, S x1, S v1,
                                S peak) {
  if (!VINES_UNLIKELY(top_bound(x0, v0, x1, v1, m.period) > peak)) return S(0);
  return numeric::quintic_abs_max(x0, v0, m.top_a(z0, a0), x1, v1, m.top_a(z1, a1), m.period);
}

// Peak of the top floor over a sub-step of length h (cubic Hermite) that
// ends t1 into the sensor step.
template <typename S, int N, typename Dev>
void update_top_peak_cubic(Data<S, N, Dev>& d, S x0, S v0, S x1, S v1, S h, S t1) {
  if (top_bound(x0, v0, x1, v1, h) <= d.peak_top) return;
  const S p = std::fmax(numeric::Cubic<S>::make(x0, v0, x1, v1, h).max_value(),
                        numeric::Cubic<S>::make(-x0, -v0, -x1, -v1, h).max_value());
  if (p > d.peak_top) {
    d.peak_top = p;
    d.peak_top_k = d.k;
    d.peak_top_dt = t1;
  }
}

}  // namespace detail
}  // namespace vines
