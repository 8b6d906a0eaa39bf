// Roots and wide sums for the fixed-point scalar (fixed.hpp), in integer
// arithmetic with bounded work, so that they give the same bits on every
// core: the contact variable q = d^{1/4} needs square roots, and the energy
// ledger sums products over a whole record, past an int32's range and
// resolution.
//   isqrt64(v)      floor(sqrt(v)) of a 64-bit integer, 32 rounds at most
//   sqrt(x)         a Fixed's square root, rounded to nearest; a negative
//                   argument gives 0 and counts as a saturation
//   Wide<G>         a signed 64-bit accumulator with G fractional bits that
//                   takes products of two Fixed<F> rounded once (F <= G <= 2F),
//                   saturating and counting like Fixed
#pragma once

#include <cstdint>
#include <limits>

#include "vines/numeric/fixed.hpp"

namespace vines::numeric {

// floor(sqrt(v)) and, in *rem, v - floor(sqrt(v))^2: digit by digit (two bits
// of v a round, at most 32 rounds).
constexpr std::uint32_t isqrt64(std::uint64_t v, std::uint64_t* rem = nullptr) {
  std::uint64_t root = 0;
  std::uint64_t bit = std::uint64_t{1} << 62;
  while (bit > v) bit >>= 2;
  while (bit != 0) {
    if (v >= root + bit) {
      v -= root + bit;
      root = (root >> 1) + bit;
    } else {
      root >>= 1;
    }
    bit >>= 2;
  }
  if (rem) *rem = v;
  return static_cast<std::uint32_t>(root);
}

// sqrt(x) in Q(31-F).F: sqrt(raw 2^-F) = sqrt(raw 2^F) 2^-F, rounded to
// nearest ((r + 1/2)^2 = r^2 + r + 1/4: up when the remainder exceeds r).
template <int F>
Fixed<F> sqrt(Fixed<F> x) {
  if (x.raw() < 0) {
    ++fixed_saturations();
    return Fixed<F>(0);
  }
  std::uint64_t rem = 0;
  const std::uint64_t r = isqrt64(static_cast<std::uint64_t>(x.raw()) << F, &rem);
  return Fixed<F>::from_raw(static_cast<std::int32_t>(rem > r ? r + 1 : r));
}

template <int G>
class Wide {
  static_assert(G > 0 && G < 63, "Q format: 1..62 fractional bits in an int64");

 public:
  using Raw = std::int64_t;
  static constexpr int kFractionBits = G;

  Wide() = default;
  static Wide from_raw(Raw r) {
    Wide w;
    w.raw_ = r;
    return w;
  }
  template <int F>
  static Wide of(Fixed<F> x) {
    static_assert(F <= G, "a Wide holds a Fixed's bits exactly");
    return from_raw(static_cast<Raw>(x.raw()) * (Raw{1} << (G - F)));
  }

  Raw raw() const { return raw_; }
  explicit operator double() const { return static_cast<double>(raw_) / static_cast<double>(Raw{1} << G); }

  Wide& operator+=(Wide b) {
    raw_ = add(raw_, b.raw_);
    return *this;
  }
  // += a b, the product (2F fractional bits, exact in 64 bits) rounded to
  // nearest once, to G bits.
  template <int F>
  Wide& add_product(Fixed<F> a, Fixed<F> b) {
    static_assert(F <= G && G <= 2 * F, "the product's bits: F <= G <= 2F");
    Raw p = static_cast<Raw>(a.raw()) * b.raw();
    if constexpr (2 * F > G) p = (p + (Raw{1} << (2 * F - G - 1))) >> (2 * F - G);
    raw_ = add(raw_, p);
    return *this;
  }
  // The sum in Q(31-F).F, rounded to nearest, saturated.
  template <int F>
  Fixed<F> to_fixed() const {
    static_assert(F <= G, "to fewer fractional bits");
    Raw v = raw_;
    if constexpr (G > F) v = (v >> (G - F)) + ((v >> (G - F - 1)) & 1);
    return Fixed<F>::saturated(v);
  }

 private:
  static Raw add(Raw a, Raw b) {
    Raw s;
    if (__builtin_add_overflow(a, b, &s)) {
      ++fixed_saturations();
      return b > 0 ? std::numeric_limits<Raw>::max() : std::numeric_limits<Raw>::min();
    }
    return s;
  }

  Raw raw_ = 0;
};

}  // namespace vines::numeric
