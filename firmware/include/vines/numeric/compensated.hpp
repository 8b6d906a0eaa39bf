// Long sums of a loop's per-step increments in the loop's scalar S: E_e
// (an integral over the whole record, 10^4-10^5 steps), the energy ledger's
// work sums, the strain increments. Sum<S> adds increments of S.
//   - S = double: the plain sum, one double, `s += x` (the loop's double
//     results are those of a plain double sum, bit for bit).
//   - S = float: a float pair (hi, lo): each increment is added to hi and the
//     rounding error of that addition, found exactly by Knuth's TwoSum (six
//     float additions, no branch), is added to lo. The sum is hi + lo, about
//     as accurate as a double sum of the same float increments (error
//     ~ n eps^2 sum |x| for n increments, eps = 2^-24, against n eps sum |x|
//     for a plain float sum), with no double arithmetic on the step: on a
//     Cortex-M4F (single-precision FPU only) a double addition is a software
//     call of ~60-100 instructions, these six additions are six instructions.
// Needs IEEE float arithmetic as written: no -ffast-math or
// -fassociative-math (which would fold TwoSum's error to zero); contraction
// into fused multiply-adds does not touch it (no products).
// value() is the sum in S (what the step computes with: the ledger's
// residual); wide() is the sum in double, read off the step (the host's and
// the link's outputs).
#pragma once

#include <type_traits>

namespace vines::numeric {

// a + b = s + e exactly (s = fl(a + b)); any a, b (Knuth's TwoSum).
template <typename S>
inline void two_sum(S a, S b, S* s, S* e) {
  const S x = a + b;
  const S bv = x - a;
  const S av = x - bv;
  *s = x;
  *e = (a - av) + (b - bv);
}

template <typename S, typename = void>
struct Sum {
  S s = S(0);
  void add(S x) { s += x; }
  void sub(S x) { s -= x; }
  S value() const { return s; }
  double wide() const { return static_cast<double>(s); }
};

template <typename S>
struct Sum<S, std::enable_if_t<std::is_same_v<S, float>>> {
  S hi = S(0), lo = S(0);
  void add(S x) {
    S e;
    two_sum(hi, x, &hi, &e);
    lo += e;
  }
  void sub(S x) { add(-x); }
  S value() const { return hi + lo; }
  double wide() const { return static_cast<double>(hi) + static_cast<double>(lo); }
};

}  // namespace vines::numeric
