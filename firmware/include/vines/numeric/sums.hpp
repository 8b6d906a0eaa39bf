// Dot products folded to SIMD lanes, and four lane sums at once: the
// readouts of the modal step (step_read in lti.hpp) are four dot products
// over the modes each step. Each is first folded to one pack of L scalars
// (L: the target's SIMD width, the modes padded to a multiple of it), then
// the four packs are summed across their lanes together. On x86 AVX with
// four doubles that is two horizontal adds, a lane swap and an add: five
// instructions for the four sums, against four for each one on its own.
// Elsewhere (L = 1 on a Cortex-M, float, no AVX) each is summed on its own.
#pragma once

#include <type_traits>

#include <Eigen/Core>

#include "vines/numeric/inline.hpp"

#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace vines::numeric {

template <typename S, int L>
using Lanes = Eigen::Array<S, L, 1>;

// The sum over the packs k of x[k..k+L) * y[k..k+L) (x, y: P scalars),
// and the same added to acc.
template <int L, int P, typename S, typename X, typename Y>
VINES_INLINE void fold_dot_add(Lanes<S, L>& acc, const X& x, const Y& y) {
  static_assert(P % L == 0, "modes are padded to whole packs");
  for (int k = 0; k < P; k += L) acc += x.template segment<L>(k) * y.template segment<L>(k);
}
template <int L, int P, typename S, typename X, typename Y>
VINES_INLINE Lanes<S, L> fold_dot(const X& x, const Y& y) {
  Lanes<S, L> acc = x.template head<L>() * y.template head<L>();
  if constexpr (P > L) fold_dot_add<L, P - L>(acc, x.template tail<P - L>(), y.template tail<P - L>());
  return acc;
}

// The lane sums of a, b, c, d, in that order.
template <typename S, int L>
VINES_INLINE Lanes<S, 4> lane_sums(const Lanes<S, L>& a, const Lanes<S, L>& b, const Lanes<S, L>& c,
                                   const Lanes<S, L>& d) {
#if defined(__AVX__)
  if constexpr (std::is_same_v<S, double> && L == 4) {
    const __m256d ab = _mm256_hadd_pd(_mm256_loadu_pd(a.data()), _mm256_loadu_pd(b.data()));  // a01 b01 a23 b23
    const __m256d cd = _mm256_hadd_pd(_mm256_loadu_pd(c.data()), _mm256_loadu_pd(d.data()));  // c01 d01 c23 d23
    Lanes<S, 4> out;
    _mm256_storeu_pd(out.data(), _mm256_add_pd(_mm256_permute2f128_pd(ab, cd, 0x20),    // a01 b01 c01 d01
                                               _mm256_permute2f128_pd(ab, cd, 0x31)));  // a23 b23 c23 d23
    return out;
  }
#endif
  Lanes<S, 4> out;
  out << a.sum(), b.sum(), c.sum(), d.sum();
  return out;
}

}  // namespace vines::numeric
