// A constant factor of any magnitude for the fixed-point scalar (fixed.hpp):
// a mantissa in Q1.30 (|m| in [1/2, 1), or 0) and a power of two, like a
// float whose exponent is fixed when the model is built. x * g is one 64-bit
// product and one shift, rounded to nearest and saturated (and counted)
// like Fixed's own product, whatever the factor's size: the fixed-point
// loop moves quantities between units far apart (an overlap of a few
// millimetres against the box's decimetres, a mode's tenth derivative)
// without a format per pair of units.
#pragma once

#include <cmath>
#include <cstdint>

#include "vines/numeric/fixed.hpp"

namespace vines::numeric {

class Gain {
 public:
  Gain() = default;
  // From a real factor (host or build side: frexp and a rounding in double).
  explicit Gain(double v) {
    if (!(v == v) || v == 0.0) return;
    int e = 0;
    const double m = std::frexp(v, &e);  // v = m 2^e, |m| in [1/2, 1)
    std::int64_t raw = std::llround(std::ldexp(m, 30));
    if (raw == (std::int64_t{1} << 30) || raw == -(std::int64_t{1} << 30)) {
      raw /= 2;
      ++e;
    }
    mant_ = static_cast<std::int32_t>(raw);
    exp_ = e;
  }
  static Gain from_parts(std::int32_t mant, int exp) {
    Gain g;
    g.mant_ = mant;
    g.exp_ = exp;
    return g;
  }
  std::int32_t mantissa() const { return mant_; }
  int exponent() const { return exp_; }
  explicit operator double() const { return std::ldexp(static_cast<double>(mant_), exp_ - 30); }
  // 2^n, with no floating point.
  static Gain pow2(int n) { return from_parts(std::int32_t{1} << 29, n + 1); }
  // This factor times 2^n, exactly.
  Gain shifted(int n) const { return from_parts(mant_, exp_ + n); }

  // x g in x's format but 64 bits wide, rounded to nearest and not yet
  // saturated (a product beyond +-2^62 is held there, which saturates any
  // Fixed): a sum of such products saturates once, at its end, so terms
  // that cancel (a mode's part of a floor's motion against the others')
  // may each pass the format's range.
  template <int F>
  friend std::int64_t wide_product(Fixed<F> x, Gain g) {
    constexpr std::int64_t kHeld = std::int64_t{1} << 62;
    const std::int64_t p = std::int64_t{x.raw()} * g.mant_;
    const int shift = 30 - g.exp_;
    if (shift <= 0) {
      if (p == 0) return 0;
      if (shift < -32) return p > 0 ? kHeld : -kHeld;
      const std::int64_t limit = std::int64_t{1} << (62 + shift);  // |p| below it: no overflow
      if (p >= limit || p <= -limit) return p > 0 ? kHeld : -kHeld;
      return p * (std::int64_t{1} << -shift);
    }
    if (shift >= 63) return 0;
    return (p + (std::int64_t{1} << (shift - 1))) >> shift;
  }
  // x g: (raw m) 2^(e - 30), rounded to nearest, saturated.
  template <int F>
  friend Fixed<F> operator*(Fixed<F> x, Gain g) {
    return Fixed<F>::saturated(wide_product(x, g));
  }
  template <int F>
  friend Fixed<F> operator*(Gain g, Fixed<F> x) {
    return x * g;
  }

  // A 64-bit raw value x (any format) times g, in x's format: the 94-bit
  // product in two 32 x 32 halves (no 128-bit type on a Cortex-M), rounded
  // to nearest; beyond +-2^62 held there and counted as a saturation. For
  // the wide sums of the energy ledger (fixed/ledger.hpp): a product of two
  // Fixed, exact in 64 bits, scaled once.
  friend std::int64_t wide_times(std::int64_t x, Gain g) {
    constexpr std::uint64_t kHeld = std::uint64_t{1} << 62;
    if (x == 0 || g.mant_ == 0) return 0;
    const bool negative = (x < 0) != (g.mant_ < 0);
    const std::uint64_t ax = x < 0 ? 0 - static_cast<std::uint64_t>(x) : static_cast<std::uint64_t>(x);
    const std::uint64_t am = static_cast<std::uint64_t>(g.mant_ < 0 ? -std::int64_t{g.mant_} : g.mant_);
    const std::uint64_t lo = (ax & 0xffffffffu) * am, hi = (ax >> 32) * am;  // x m = hi 2^32 + lo, each < 2^62
    const int shift = 30 - g.exp_;
    std::uint64_t r = kHeld;
    if (shift >= 96) {
      r = 0;
    } else if (shift > 32) {  // floor((hi + 2^(shift-33)) + lo / 2^32) / 2^(shift-32)): rounded
      const int s = shift - 32;
      r = (hi + (lo >> 32) + (std::uint64_t{1} << (s - 1))) >> s;
    } else if (shift > 0) {
      const int up = 32 - shift;  // hi 2^up + (lo + 2^(shift-1)) 2^-shift
      if (hi < (kHeld >> up)) r = (hi << up) + ((lo + (std::uint64_t{1} << (shift - 1))) >> shift);
    } else if (-shift <= 62) {  // hi 2^(32+up) + lo 2^up, each below 2^62
      const int up = -shift;
      const bool hi_fits = up < 30 ? hi < (kHeld >> (32 + up)) : hi == 0;
      if (hi_fits && lo < (kHeld >> up)) r = (hi == 0 ? 0 : hi << (32 + up)) + (lo << up);
    }
    if (r >= kHeld) {
      r = kHeld;
      ++fixed_saturations();
    }
    return negative ? -static_cast<std::int64_t>(r) : static_cast<std::int64_t>(r);
  }

 private:
  std::int32_t mant_ = 0;
  int exp_ = 0;
};

}  // namespace vines::numeric
