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
//   power(x, a, b)  x^(a/b) for x > 0 through a base-2 logarithm and
//                   exponential with kLogBits fractional bits (relative error
//                   below 2^-9): the split contact step's step-size rule
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

// Fractional bits of the base-2 logarithm power() goes through.
inline constexpr int kLogBits = 12;

// floor(2^kLogBits log2(raw 2^-F)) of a positive raw value: the integer
// part from the leading bit, each fractional bit by squaring the mantissa
// (in [1, 2), Q1.30) once.
template <int F>
constexpr std::int32_t log2_raw(std::uint32_t raw) {
  int lead = 31;
  while (!(raw >> lead)) --lead;
  std::int32_t out = (lead - F) * (std::int32_t{1} << kLogBits);
  std::uint64_t m = lead >= 30 ? raw >> (lead - 30) : std::uint64_t{raw} << (30 - lead);
  for (int bit = kLogBits - 1; bit >= 0; --bit) {
    m = (m * m) >> 30;
    if (m >> 31) {
      m >>= 1;
      out += std::int32_t{1} << bit;
    }
  }
  return out;
}

// 2^(2^-(kLogBits - i)) in Q1.30, i < kLogBits: square roots of 2, taken
// one after another in integers (floors), so the table is the same on every
// compiler.
struct Exp2Table {
  std::uint32_t v[kLogBits] = {};
  constexpr Exp2Table() {
    std::uint64_t r = isqrt64(std::uint64_t{2} << 60);  // 2^(1/2) in Q1.30
    for (int i = kLogBits - 1; i >= 0; --i) {
      v[i] = static_cast<std::uint32_t>(r);
      r = isqrt64(r << 30);
    }
  }
};

// 2^(e 2^-kLogBits) in Q(31-F).F: the fractional part as a product of the
// table's factors (each rounded), shifted by the integer part; saturated
// (and counted) past the range, 0 below its resolution.
template <int F>
Fixed<F> exp2_raw(std::int32_t e) {
  static constexpr Exp2Table kTable{};
  const std::int32_t whole = e >> kLogBits;  // floor
  std::uint64_t v = std::uint64_t{1} << 30;
  for (int i = 0; i < kLogBits; ++i)
    if ((e >> i) & 1) v = (v * kTable.v[i] + (std::uint64_t{1} << 29)) >> 30;
  const int shift = whole + F - 30;
  if (shift >= 0) return Fixed<F>::saturated(shift > 32 ? std::int64_t{1} << 62 : static_cast<std::int64_t>(v << shift));
  if (shift < -40) return Fixed<F>(0);
  return Fixed<F>::from_raw(static_cast<std::int32_t>((v + (std::uint64_t{1} << (-shift - 1))) >> -shift));
}

// x^(a/b) for x > 0 (b > 0); 0 for x <= 0. Bounded work: kLogBits squarings
// and at most kLogBits products.
template <int F>
Fixed<F> power(Fixed<F> x, int a, int b) {
  if (x.raw() <= 0) return Fixed<F>(0);
  const std::int64_t l = std::int64_t{log2_raw<F>(static_cast<std::uint32_t>(x.raw()))} * a;
  const std::int64_t e = l >= 0 ? l / b : -((-l + b - 1) / b);  // floor
  return exp2_raw<F>(static_cast<std::int32_t>(e));
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
