// Fixed-point scalar for FPU-less cores: Q(31-F).F in an int32, every
// operation saturating (to the largest/smallest value; each saturation is
// counted in fixed_saturations()), products rounded to nearest through a
// 64-bit intermediate (one SMULL on a Cortex-M3/M4). With Eigen::NumTraits,
// so Eigen arrays and the core's templates take it as their scalar.
//
// Its range is +-2^(31-F) and its resolution 2^-F: quantities must be scaled
// to O(1) first. fixed_modal.hpp does this for the modal exact step (the
// linear frame propagation); see there for where it is and is not fit.
// fixed_math.hpp has its square root and a 64-bit accumulator.
#pragma once

#include <cstdint>
#include <limits>

#include <Eigen/Core>

namespace vines::numeric {

// How many operations saturated since the counter was last reset. A board
// has one core and no threads: a plain counter. On a host each thread counts
// its own (the runs of a study share a pool of threads).
#if defined(__arm__) && !defined(__linux__)
#define VINES_FIXED_COUNTER static
#else
#define VINES_FIXED_COUNTER static thread_local
#endif
inline std::uint32_t& fixed_saturations() {
  VINES_FIXED_COUNTER std::uint32_t count = 0;
  return count;
}
#undef VINES_FIXED_COUNTER

template <int F>
class Fixed {
  static_assert(F > 0 && F < 31, "Q format: 1..30 fractional bits in an int32");

 public:
  using Raw = std::int32_t;
  static constexpr int kFractionBits = F;
  static constexpr double kOne = static_cast<double>(std::int64_t{1} << F);

  Fixed() = default;
  // From a real value: rounded to nearest, saturated (NaN gives 0).
  explicit Fixed(double v) : raw_(from_double(v)) {}
  explicit Fixed(int v) : raw_(saturate(static_cast<std::int64_t>(v) * (std::int64_t{1} << F))) {}
  static Fixed from_raw(Raw r) {
    Fixed x;
    x.raw_ = r;
    return x;
  }
  // From a wider raw value in the same format: saturated (and counted).
  static Fixed saturated(std::int64_t r) { return from_raw(saturate(r)); }

  Raw raw() const { return raw_; }
  explicit operator double() const { return static_cast<double>(raw_) / kOne; }
  explicit operator float() const { return static_cast<float>(static_cast<double>(*this)); }

  // Sums in 32 bits with the overflow flag (one add and a branch on a
  // Cortex-M), the saturated value the 64-bit sum would give.
  friend Fixed operator+(Fixed a, Fixed b) {
    Raw r;
    if (__builtin_add_overflow(a.raw_, b.raw_, &r)) return from_raw(overflowed(b.raw_ > 0));
    return from_raw(r);
  }
  friend Fixed operator-(Fixed a, Fixed b) {
    Raw r;
    if (__builtin_sub_overflow(a.raw_, b.raw_, &r)) return from_raw(overflowed(b.raw_ < 0));
    return from_raw(r);
  }
  friend Fixed operator-(Fixed a) { return from_raw(saturate(-std::int64_t{a.raw_})); }
  friend Fixed operator*(Fixed a, Fixed b) {
    const std::int64_t p = std::int64_t{a.raw_} * b.raw_ + (std::int64_t{1} << (F - 1));
    return from_raw(saturate(p >> F));  // arithmetic shift: floor, so + half rounds to nearest
  }
  friend Fixed operator/(Fixed a, Fixed b) {
    if (b.raw_ == 0) return from_raw(saturate(a.raw_ >= 0 ? std::int64_t{1} << 62 : -(std::int64_t{1} << 62)));
    return from_raw(saturate((std::int64_t{a.raw_} * (std::int64_t{1} << F)) / b.raw_));
  }
  // By an integer: the quotient a / (b 2^F) of the division above, bit for
  // bit (both truncate the same rational), in one 32-bit division (a
  // Cortex-M3's SDIV, not the 64-bit library division above).
  friend Fixed operator/(Fixed a, int b) {
    if (b == 0) return from_raw(saturate(a.raw_ >= 0 ? std::int64_t{1} << 62 : -(std::int64_t{1} << 62)));
    if (b == -1) return -a;
    return from_raw(static_cast<Raw>(a.raw_ / b));
  }
  // By a positive integer, rounded to nearest, ties to even: the unbiased
  // sibling of the division above, for sums that repeat it.
  friend Fixed div_rounded(Fixed a, int b) {
    const Raw q = a.raw_ / b, r = a.raw_ - q * b;  // q truncated, r of a's sign
    const Raw twice = r < 0 ? -2 * r : 2 * r, away = r < 0 ? -1 : 1;
    return from_raw(twice > b || (twice == b && (q & 1)) ? q + away : q);
  }
  Fixed& operator+=(Fixed b) { return *this = *this + b; }
  Fixed& operator-=(Fixed b) { return *this = *this - b; }
  Fixed& operator*=(Fixed b) { return *this = *this * b; }
  Fixed& operator/=(Fixed b) { return *this = *this / b; }

  friend bool operator==(Fixed a, Fixed b) { return a.raw_ == b.raw_; }
  friend bool operator!=(Fixed a, Fixed b) { return a.raw_ != b.raw_; }
  friend bool operator<(Fixed a, Fixed b) { return a.raw_ < b.raw_; }
  friend bool operator>(Fixed a, Fixed b) { return a.raw_ > b.raw_; }
  friend bool operator<=(Fixed a, Fixed b) { return a.raw_ <= b.raw_; }
  friend bool operator>=(Fixed a, Fixed b) { return a.raw_ >= b.raw_; }

  static Fixed max() { return from_raw(std::numeric_limits<Raw>::max()); }
  static Fixed lowest() { return from_raw(std::numeric_limits<Raw>::min()); }
  static Fixed epsilon() { return from_raw(1); }

 private:
  static Raw overflowed(bool up) {
    ++fixed_saturations();
    return up ? std::numeric_limits<Raw>::max() : std::numeric_limits<Raw>::min();
  }
  static Raw saturate(std::int64_t v) {
    const Raw r = static_cast<Raw>(v);
    if (r == v) return r;  // in range (one compare of the high word on a 32-bit core)
    return overflowed(v > 0);
  }
  static Raw from_double(double v) {
    if (!(v == v)) return 0;
    const double scaled = v * kOne;
    if (scaled >= 2147483647.0) return saturate(std::int64_t{1} << 40);
    if (scaled <= -2147483648.0) return saturate(-(std::int64_t{1} << 40));
    return static_cast<Raw>(scaled < 0 ? scaled - 0.5 : scaled + 0.5);  // to nearest, ties away
  }

  Raw raw_;
};

template <int F>
Fixed<F> abs(Fixed<F> x) {
  return x < Fixed<F>(0) ? -x : x;
}
template <int F>
Fixed<F> fabs(Fixed<F> x) {
  return abs(x);
}

}  // namespace vines::numeric

namespace Eigen {

template <int F>
struct NumTraits<vines::numeric::Fixed<F>> : GenericNumTraits<vines::numeric::Fixed<F>> {
  using Fx = vines::numeric::Fixed<F>;
  using Real = Fx;
  using NonInteger = Fx;
  using Literal = Fx;
  using Nested = Fx;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 0,
    ReadCost = 1,
    AddCost = 2,  // add, then the saturation test
    MulCost = 4,  // 64-bit product, round, shift, saturation test
  };
  static Fx epsilon() { return Fx::epsilon(); }
  static Fx dummy_precision() { return Fx::from_raw(16); }
  static Fx highest() { return Fx::max(); }
  static Fx lowest() { return Fx::lowest(); }
  static int digits10() { return static_cast<int>(F * 0.30103); }
};

}  // namespace Eigen
