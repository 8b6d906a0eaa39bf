// Fixed-point scalar (vines/numeric/fixed.hpp): saturating Q arithmetic, and
// the modal exact step in Q3.28 (fixed_modal.hpp) against double on El Centro
// for the bare frame (top-floor displacement, every sample of the record).
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "support.hpp"
#include "vines/build/build_model.hpp"
#include "vines/fixed/modal.hpp"
#include "vines/numeric/fixed_gain.hpp"
#include "vines/numeric/fixed_math.hpp"

namespace vines {
namespace {

using numeric::Fixed;
using numeric::fixed_saturations;
using Q = Fixed<28>;

TEST(Fixed, RoundsToNearestAndSaturates) {
  EXPECT_EQ(Q(1.5).raw(), 3 << 27);
  EXPECT_EQ(Q(0.25) * Q(-2.0), Q(-0.5));
  EXPECT_EQ(Q::from_raw(3) * Q(0.5), Q::from_raw(2));  // 1.5 ulp rounds to 2
  EXPECT_DOUBLE_EQ(static_cast<double>(Q(3.0) / Q(4.0)), 0.75);
  fixed_saturations() = 0;
  EXPECT_EQ(Q(7.5) + Q(7.5), Q::max());  // range is [-8, 8)
  EXPECT_EQ(Q(-7.5) - Q(7.5), Q::lowest());
  EXPECT_EQ(Q(4.0) * Q(-4.0), Q::lowest());
  EXPECT_EQ(Q(1e9), Q::max());
  EXPECT_EQ(fixed_saturations(), 4u);
}

// A division by an integer (one 32-bit division) is the division by that
// integer as a Fixed (64-bit), bit for bit: random values and the range's
// edges, every divisor the contact step uses and their negatives.
TEST(Fixed, DivisionByAnIntegerIsTheFixedDivision) {
  std::mt19937 rng(34);
  std::uniform_int_distribution<std::int32_t> raw(std::numeric_limits<std::int32_t>::min(),
                                                  std::numeric_limits<std::int32_t>::max());
  std::vector<Q> values{Q::max(), Q::lowest(), Q::from_raw(1), Q::from_raw(-1), Q(0.0), Q(7.0), Q(-5.0)};
  for (int i = 0; i < 100000; ++i) values.push_back(Q::from_raw(raw(rng)));
  fixed_saturations() = 0;
  for (const Q x : values)
    for (int d : {1, 2, 3, 4, 5, 6, 7, -1, -2, -6}) ASSERT_EQ((x / d).raw(), (x / Q(d)).raw()) << x.raw() << " / " << d;
  const std::uint32_t both = fixed_saturations();  // Q::lowest() / -1, counted once by each
  EXPECT_EQ(both, 2u);
}

// The rounded division (the contact's Runge-Kutta sums, numeric/rk4.hpp)
// is the nearest integer to raw / d, ties to even, against long double:
// random values, the range's edges and every tie.
TEST(Fixed, RoundedDivisionIsTheNearestTiesToEven) {
  std::mt19937 rng(35);
  std::uniform_int_distribution<std::int32_t> raw(std::numeric_limits<std::int32_t>::min(),
                                                  std::numeric_limits<std::int32_t>::max());
  std::vector<std::int32_t> values{std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::min(),
                                   0, 1, -1, 2, -2, 3, -3, 5, -5, 9, -9, 15, -15};
  for (int i = 0; i < 100000; ++i) values.push_back(raw(rng));
  fixed_saturations() = 0;
  int ties = 0;
  for (const std::int32_t v : values)
    for (int d : {2, 3, 6}) {
      const long double exact = static_cast<long double>(v) / d;
      ties += 2 * (v % d) == d || 2 * (v % d) == -d;
      const auto expected = static_cast<std::int32_t>(std::nearbyintl(exact));  // the default mode: ties to even
      ASSERT_EQ(div_rounded(Q::from_raw(v), d).raw(), expected) << v << " / " << d;
    }
  EXPECT_GT(ties, 50000);
  EXPECT_EQ(fixed_saturations(), 0u);
}

TEST(Fixed, EigenArraysTakeIt) {
  Eigen::Matrix<Q, 3, 1> a, b;
  a << Q(1.0), Q(-2.0), Q(0.5);
  b << Q(0.5), Q(0.25), Q(-4.0);
  const Eigen::Matrix<Q, 3, 1> c = a.array() * b.array() + a.array() * Q(2.0);
  EXPECT_EQ(c(0), Q(2.5));
  EXPECT_EQ(c(1), Q(-4.5));
  EXPECT_EQ(c(2), Q(-1.0));
}

// isqrt64 against the defining inequalities r^2 <= v < (r + 1)^2, on the
// edges (0, squares and their neighbours, 2^64 - 1) and on random values.
TEST(FixedMath, IntegerSquareRootIsTheFloor) {
  auto check = [](std::uint64_t v) {
    std::uint64_t rem = 0;
    const std::uint64_t r = numeric::isqrt64(v, &rem);
    const unsigned __int128 r2 = static_cast<unsigned __int128>(r) * r;
    const unsigned __int128 next = static_cast<unsigned __int128>(r + 1) * (r + 1);
    EXPECT_TRUE(r2 <= v && v < next) << v;
    EXPECT_EQ(rem, v - static_cast<std::uint64_t>(r2)) << v;
  };
  for (std::uint64_t v : {0ull, 1ull, 2ull, 3ull, 4ull, 15ull, 16ull, 17ull, ~0ull, ~0ull - 1})
    check(v);
  for (std::uint64_t r : {1ull, 3ull, 65535ull, 65536ull, 4294967295ull}) {
    check(r * r);
    check(r * r - 1);
    check(r * r + 1);
  }
  std::mt19937_64 rng(7);
  for (int i = 0; i < 100000; ++i) check(rng() >> (rng() % 64));
}

// Fixed sqrt is the real root rounded to nearest: within half an ulp of the
// long double root, over the whole positive range of Q3.28.
TEST(FixedMath, SquareRootRoundsToNearest) {
  std::mt19937 rng(11);
  fixed_saturations() = 0;
  for (int i = 0; i < 100000; ++i) {
    const Q x = Q::from_raw(static_cast<std::int32_t>(rng() >> 1));
    const long double exact = std::sqrt(static_cast<long double>(x.raw()) / Q::kOne) * Q::kOne;
    const Q r = numeric::sqrt(x);
    EXPECT_LE(std::fabs(static_cast<long double>(r.raw()) - exact), 0.5L) << x.raw();
  }
  EXPECT_EQ(numeric::sqrt(Q(0.0)), Q(0.0));
  EXPECT_EQ(numeric::sqrt(Q(4.0)), Q(2.0));
  EXPECT_EQ(fixed_saturations(), 0u);
  EXPECT_EQ(numeric::sqrt(Q(-1.0)), Q(0.0));  // a domain error is a counted clamp
  EXPECT_EQ(fixed_saturations(), 1u);
}

// A Wide sum of products equals the exactly rounded sum (products summed in
// long double, exact here), and saturates visibly past its range.
TEST(FixedMath, WideSumsProductsRoundedOnce) {
  using W = numeric::Wide<40>;
  std::mt19937 rng(3);
  W w;
  __int128 exact = 0;  // in 2^-56
  for (int i = 0; i < 200000; ++i) {
    const Q a = Q::from_raw(static_cast<std::int32_t>(rng())), b = Q::from_raw(static_cast<std::int32_t>(rng()));
    w.add_product(a, b);
    exact += static_cast<__int128>(a.raw()) * b.raw();
  }
  // Each product is rounded to 2^-40 once: the sum is within n/2 ulps.
  const long double diff = static_cast<long double>(static_cast<__int128>(w.raw()) * 65536 - exact) / 65536.0L;
  EXPECT_LE(std::fabs(diff), 200000 * 0.5L);
  EXPECT_EQ(W::of(Q(1.5)).to_fixed<28>(), Q(1.5));
  fixed_saturations() = 0;
  W big = W::from_raw(std::numeric_limits<std::int64_t>::max() - 1);
  big.add_product(Q(1.0), Q(1.0));
  EXPECT_EQ(big.raw(), std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(W::of(Q(7.0)).add_product(Q(7.0), Q(7.0)).to_fixed<28>(), Q::max());  // 56 > 8
  EXPECT_EQ(fixed_saturations(), 2u);
}

// A 64-bit raw value times a Gain (the energy ledger's sums): the exact
// 94-bit product rounded to nearest (ties away from zero), held at 2^62 and
// counted beyond it, for every shift of the gain's exponent.
TEST(FixedMath, WideTimesIsTheRoundedExactProduct) {
  std::mt19937_64 rng(5);
  constexpr __int128 kHeld = static_cast<__int128>(1) << 62;
  int held = 0;
  fixed_saturations() = 0;
  for (int i = 0; i < 400000; ++i) {
    const int bits = static_cast<int>(rng() % 63);
    const std::int64_t x = static_cast<std::int64_t>(rng() >> (63 - bits)) * ((rng() & 1) ? 1 : -1);
    const int exp = static_cast<int>(rng() % 120) - 90;
    const auto mant = static_cast<std::int32_t>((rng() % (1u << 29)) + (1u << 29)) * ((rng() & 1) ? 1 : -1);
    const numeric::Gain g = numeric::Gain::from_parts(mant, exp);
    const __int128 p = static_cast<__int128>(x) * mant, ap = p < 0 ? -p : p;
    const int shift = 30 - exp;
    __int128 r = shift >= 100 ? 0 : shift > 0 ? (ap + (static_cast<__int128>(1) << (shift - 1))) >> shift
                                              : (-shift > 62 || ap >= (kHeld >> -shift) ? kHeld : ap << -shift);
    if (r >= kHeld) {
      r = kHeld;
      ++held;
    }
    const __int128 want = p < 0 ? -r : r;
    ASSERT_EQ(wide_times(x, g), static_cast<std::int64_t>(want)) << x << " " << mant << " 2^" << exp;
  }
  EXPECT_GT(held, 1000);
  EXPECT_EQ(fixed_saturations(), static_cast<std::uint32_t>(held));
}

// Each host thread counts its own saturations (a study's runs share a pool).
// power(x, a, b) = x^(a/b) through the integer base-2 logarithm and
// exponential: relative error below 2^-9 (past the result's rounding, half
// a unit of 2^-28) over Q3.28's range, the exponents
// the split step's rule takes and others; 0 for x <= 0; saturation counted
// past the range.
TEST(FixedMath, PowerIsWithinItsBound) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> log_x(-20.0, 2.9);
  const int exps[][2] = {{1, 10}, {1, 6}, {2, 3}, {1, 2}, {-2, 5}, {3, 2}, {1, 1}};
  double worst = 0;
  fixed_saturations() = 0;
  for (const auto& ab : exps) {
    for (int i = 0; i < 20000; ++i) {
      const Q x(std::exp2(log_x(rng)));
      const double want = std::pow(static_cast<double>(x), static_cast<double>(ab[0]) / ab[1]);
      if (want >= 8.0 || want < 1e-6) continue;
      const double got = static_cast<double>(numeric::power(x, ab[0], ab[1]));
      worst = std::fmax(worst, (std::fabs(got - want) - 0.5 / Q::kOne) / want);
    }
  }
  std::printf("power: largest relative error %.3g (2^-9 = %.3g)\n", worst, std::exp2(-9.0));
  EXPECT_LT(worst, std::exp2(-9.0));
  EXPECT_EQ(fixed_saturations(), 0u);
  EXPECT_EQ(numeric::power(Q(0.0), 1, 10), Q(0.0));
  EXPECT_EQ(numeric::power(Q(-1.0), 1, 2), Q(0.0));
  EXPECT_EQ(numeric::power(Q(1.0), 1, 7), Q(1.0));
  EXPECT_EQ(numeric::power(Q(4.0), 3, 1), Q::max());  // 64: past the range, counted
  EXPECT_EQ(fixed_saturations(), 1u);
}

TEST(FixedMath, EachThreadCountsItsOwnSaturations) {
  fixed_saturations() = 0;
  std::uint32_t other = 99;
  std::thread t([&] {
    fixed_saturations() = 0;
    for (int i = 0; i < 3; ++i) (void)(Q(7.0) + Q(7.0));
    other = fixed_saturations();
  });
  t.join();
  EXPECT_EQ(other, 3u);
  EXPECT_EQ(fixed_saturations(), 0u);
}

// The bare frame of docs/model.md section 2 at 1 kHz: top-floor displacement from the double
// step and from the Q3.28 step (scales: 10x the static response to the PGA).
struct FixedRun {
  double peak_double = 0, peak_fixed = 0, max_abs_error = 0;
  std::uint32_t saturations = 0;
};

FixedRun run_fixed(double amplification) {
  static Model<double, 10, NoDevice> m;
  EXPECT_TRUE(build_model(test::paper_scene(DeviceKind::kNone), &m).ok());
  const std::vector<double> a = test::elcentro(1000.0);
  double pga = 0;
  for (double x : a) pga = std::fmax(pga, std::fabs(x));
  const auto scales = numeric::modal_scales<10>(m.modal.omega, m.modal.gamma, pga, amplification);
  const auto lq = numeric::scaled_modal<28, 10>(m.lti, scales);
  using ZD = Model<double, 10, NoDevice>::VecX;  // modes padded to the build's SIMD width
  using ZQ = Eigen::Matrix<Q, ZD::RowsAtCompileTime, 1>;
  ZD zd = ZD::Zero();
  ZQ zq;
  zq.setConstant(Q(0));
  fixed_saturations() = 0;
  FixedRun r;
  for (std::size_t k = 1; k < a.size(); ++k) {
    m.lti.step(zd, a[k - 1], a[k]);
    lq.step(zq, Q(a[k - 1] / pga), Q(a[k] / pga));
    double x_fixed = 0;
    for (int j = 0; j < 10; ++j) x_fixed += m.rows.top(j) * scales.q(j) * static_cast<double>(zq(j));
    const double x_double = m.top_x(zd);
    r.peak_double = std::fmax(r.peak_double, std::fabs(x_double));
    r.peak_fixed = std::fmax(r.peak_fixed, std::fabs(x_fixed));
    r.max_abs_error = std::fmax(r.max_abs_error, std::fabs(x_fixed - x_double));
  }
  r.saturations = fixed_saturations();
  return r;
}

TEST(FixedModal, TracksDoubleOnElCentro) {
  const FixedRun r = run_fixed(10.0);
  const double rel = r.max_abs_error / r.peak_double;
  std::printf("Q3.28 modal step, El Centro, bare frame, 1 kHz: peak top %.9f m (double %.9f m), "
              "largest error %.3g m = %.3g of the peak, %u saturations\n",
              r.peak_fixed, r.peak_double, r.max_abs_error, rel, r.saturations);
  EXPECT_EQ(r.saturations, 0u);
  EXPECT_LT(rel, 5e-5);  // measured 2.4e-5 (7.9 um on 0.327 m)
  EXPECT_GT(r.peak_double, 0.1);
}

TEST(FixedModal, ScalesTooSmallSaturateVisibly) {
  const FixedRun r = run_fixed(0.1);  // state 100x larger than with the design scales
  EXPECT_GT(r.saturations, 0u);
  EXPECT_GT(r.max_abs_error / r.peak_double, 0.05);  // measured 9 %
}

}  // namespace
}  // namespace vines
