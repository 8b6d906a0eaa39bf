// The loop's long sums (numeric/compensated.hpp): in double the plain sum,
// bit for bit; in float a TwoSum pair as accurate as a double sum of the
// same float increments, where a plain float sum drifts by orders more.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include <gtest/gtest.h>

#include "vines/numeric/compensated.hpp"

namespace {

using vines::numeric::Sum;

// A record's worth of increments of mixed sign and size (an energy's
// step integrals: mostly small, a few large), from a fixed LCG.
float increment(std::uint32_t* state) {
  *state = *state * 1664525u + 1013904223u;
  const float u = static_cast<float>(*state >> 8) / 16777216.0f;  // [0, 1)
  return (u - 0.3f) * (u > 0.99f ? 1e3f : 1.0f);
}

TEST(Compensated, DoubleIsThePlainSumBitForBit) {
  std::uint32_t st = 1;
  Sum<double> s;
  double plain = 0;
  for (int i = 0; i < 100000; ++i) {
    const double x = increment(&st) * 1e-3 + 1e-9 * i;
    if (i % 7 == 3) {
      s.sub(x);
      plain -= x;
    } else {
      s.add(x);
      plain += x;
    }
  }
  const double value = s.value(), wide = s.wide();
  EXPECT_EQ(0, std::memcmp(&plain, &value, sizeof plain));
  EXPECT_EQ(0, std::memcmp(&plain, &wide, sizeof plain));
  static_assert(sizeof(Sum<double>) == sizeof(double), "the double sum is one double");
}

TEST(Compensated, FloatPairKeepsADoubleSumsAccuracy) {
  // 53,761 steps: El Centro at 1 kHz.
  std::uint32_t st = 7;
  Sum<float> s;
  float plain = 0;
  double dbl = 0;
  long double exact = 0;
  for (int i = 0; i < 53761; ++i) {
    const float x = increment(&st);
    s.add(x);
    plain += x;
    dbl += x;
    exact += x;
  }
  const double ref = static_cast<double>(exact);
  const double scale = std::fabs(ref);
  ASSERT_GT(scale, 1.0);
  const double err_pair = std::fabs(s.wide() - ref) / scale;
  const double err_float = std::fabs(static_cast<double>(plain) - ref) / scale;
  const double err_double = std::fabs(dbl - ref) / scale;
  std::printf("[ measured ] relative error: float pair %.2e, plain float %.2e, double %.2e\n", err_pair, err_float,
              err_double);
  EXPECT_LT(err_pair, 1e-10);            // a double sum's order (n eps_f^2 at worst)
  EXPECT_GT(err_float, 100 * err_pair);  // what the pair is for
  // value() is the pair rounded to one float.
  EXPECT_LE(std::fabs(static_cast<double>(s.value()) - ref) / scale, 1.2e-7);
}

TEST(Compensated, TwoSumIsExact) {
  float s, e;
  vines::numeric::two_sum(1.0f, 1e-8f, &s, &e);
  EXPECT_EQ(s, 1.0f);
  EXPECT_EQ(e, 1e-8f);
  vines::numeric::two_sum(1e-8f, -1.0f, &s, &e);
  EXPECT_EQ(s, -1.0f);
  EXPECT_EQ(e, 1e-8f);
}

}  // namespace
