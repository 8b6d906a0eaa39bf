// Host HAL backend: resampling (exact at knots, linear between, zero before t0
// and after the ramp) and the sample source with its simulated clock.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "host/record.hpp"
#include "record_support.hpp"

namespace fs = std::filesystem;
using namespace vines::hal;
using namespace vines::record_test;

namespace {

// ---- resample: exact at knots, linear between, zero before t0 and after the ramp ----

Record make_record(std::vector<double> a, double dt, double t0 = 0.0) {
  Record r;
  r.path = "mem";
  r.dt_s = dt;
  r.t0_s = t0;
  r.accel_mps2 = std::move(a);
  return r;
}

TEST(Resample, KnotsLinearAndZeroTail) {
  const Record r = make_record({1.0, 2.0, -3.0}, 0.02);
  const std::vector<double> out = resample(r, 100.0);  // two output samples per dt
  const std::vector<double> want = {1.0, 1.5, 2.0, -0.5, -3.0, -1.5, 0.0};
  ASSERT_EQ(out.size(), want.size());  // K = round(3 * 0.02 * 100) = 6
  for (std::size_t k = 0; k < want.size(); ++k) EXPECT_DOUBLE_EQ(out[k], want[k]) << k;
  EXPECT_EQ(out[0], 1.0);
  EXPECT_EQ(out[2], 2.0);
  EXPECT_EQ(out[4], -3.0);
}

TEST(Resample, OffsetStartIsZeroBeforeT0) {
  const Record r = make_record({4.0, 8.0}, 0.1, 0.25);
  const std::vector<double> out = resample(r, 20.0);        // t_k = 0, .05, ..., .45
  ASSERT_EQ(out.size(), 10u);                               // K = round(0.45 * 20) = 9
  for (int k = 0; k < 5; ++k) EXPECT_EQ(out[k], 0.0) << k;  // t < 0.25: before the record
  EXPECT_EQ(out[5], 4.0);                                   // t = 0.25: first knot
  EXPECT_DOUBLE_EQ(out[6], 6.0);                            // t = 0.30: half-way to 8
  EXPECT_EQ(out[7], 8.0);                                   // t = 0.35: last knot
  EXPECT_DOUBLE_EQ(out[8], 4.0);                            // t = 0.40: ramp to zero
  EXPECT_EQ(out[9], 0.0);                                   // t = 0.45: end of record
}

TEST(Resample, NonIntegerRatioIsLinear) {
  const Record r = make_record({0.0, 3.0, -1.0, 2.0}, 0.02);
  const double rate = 30.0;
  const std::vector<double> out = resample(r, rate);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(std::llround(0.08 * rate)) + 1);
  const double ext[] = {0.0, 3.0, -1.0, 2.0, 0.0};
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double u = static_cast<double>(k) / rate / 0.02;
    const std::size_t i = static_cast<std::size_t>(u);
    const double want = i >= 4 ? 0.0 : ext[i] + (u - i) * (ext[i + 1] - ext[i]);
    EXPECT_NEAR(out[k], want, 1e-12) << k;
  }
}

TEST(Resample, BadRateThrows) {
  const Record r = make_record({1.0}, 0.01);
  EXPECT_THROW(resample(r, 0.0), RecordError);
  EXPECT_THROW(resample(r, -5.0), RecordError);
  EXPECT_THROW(resample(r, std::nan("")), RecordError);
  EXPECT_THROW(resample(r, 1e12), RecordError);  // far too many samples
}

// Real records at sensor rates that are multiples of 1/dt: every knot bit for bit.
TEST(Resample, RealRecordsExactAtKnots) {
  const std::string dir = motions_dir();
  if (dir.empty() || !fs::is_directory(dir)) GTEST_SKIP() << "no ground-motion folder: " << dir;
  struct Case {
    const char* file;
    int column;
    double rate;
  };
  const Case cases[] = {
      {"elcentro_1940_ns_2688pts_dt002_time_g.dat", 1, 1000.0},
      {"kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2", 1, 500.0},
      {"lomaprieta_1989_corralitos_CLS000_nga_west2_rsn753.at2", 1, 1000.0},
      {"elcentro_1940_ns_peer_legacy_I-ELC180_dt001.at2", 1, 300.0},
      {"mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt", 2, 1000.0},
  };
  for (const Case& c : cases) {
    RecordSpec s = spec_for(dir + "/" + c.file);
    s.column = c.column;
    const Record r = load_record(s);
    const std::vector<double> out = resample(r, c.rate);
    const long long per = std::llround(r.dt_s * c.rate);
    const long long first = std::llround(r.t0_s * c.rate);
    const std::size_t n = r.accel_mps2.size();
    ASSERT_EQ(out.size(), static_cast<std::size_t>(first + per * static_cast<long long>(n)) + 1)
        << c.file;
    for (long long k = 0; k < first; ++k) ASSERT_EQ(out[k], 0.0) << c.file << " k=" << k;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(out[first + per * i], r.accel_mps2[i]) << c.file << " knot " << i;
    }
    // Last dt ramps linearly to zero.
    const double last = r.accel_mps2.back();
    for (long long j = 0; j <= per; ++j) {
      const std::size_t k = first + per * (n - 1) + j;
      EXPECT_NEAR(out[k], last * (1.0 - static_cast<double>(j) / per), 1e-12) << c.file;
    }
  }
}

// ---- RecordSource and SimClock ----

TEST(RecordSourceTest, HandsOutSamplesAndAdvancesClockExactly) {
  SimClock clock;
  const std::size_t n = 3001;
  std::vector<double> samples(n);
  for (std::size_t i = 0; i < n; ++i) samples[i] = 0.5 * static_cast<double>(i);
  RecordSource src(samples, 3.0, &clock);  // period 333333333.3 ns: rounding must not drift
  EXPECT_DOUBLE_EQ(src.rate_hz(), 3.0);
  EXPECT_EQ(src.size(), n);

  double a = -1.0;
  for (std::size_t k = 0; k < n; ++k) {
    ASSERT_TRUE(src.next(&a));
    ASSERT_EQ(a, samples[k]);
    ASSERT_EQ(clock.now_ns(), static_cast<std::uint64_t>(std::llround(k * 1e9 / 3.0))) << k;
    ASSERT_EQ(src.position(), k + 1);
  }
  EXPECT_EQ(clock.now_ns(), 1'000'000'000'000ull);
  // End of stream: false, nothing written, clock unchanged.
  a = 42.0;
  EXPECT_FALSE(src.next(&a));
  EXPECT_EQ(a, 42.0);
  EXPECT_EQ(clock.now_ns(), 1'000'000'000'000ull);
}

TEST(RecordSourceTest, ReadInBlocksIsNextSampleBySample) {
  const std::size_t n = 1000;
  std::vector<double> samples(n);
  for (std::size_t i = 0; i < n; ++i) samples[i] = 0.5 * static_cast<double>(i);
  for (const std::size_t block : {std::size_t{1}, std::size_t{7}, std::size_t{999}, std::size_t{4096}}) {
    SimClock clock;
    RecordSource src(samples, 3.0, &clock);
    std::vector<double> got, buf(block);
    while (const std::size_t k = src.read(buf.data(), block)) {
      got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(k));
      // The clock reads the time of the last sample handed out, as after next().
      ASSERT_EQ(clock.now_ns(), static_cast<std::uint64_t>(std::llround((got.size() - 1) * 1e9 / 3.0))) << block;
    }
    EXPECT_EQ(got, samples) << block;
    EXPECT_EQ(src.position(), n);
    double a = 0;
    EXPECT_FALSE(src.next(&a));
  }
}

TEST(RecordSourceTest, WorksWithoutClockAndRejectsBadRate) {
  const std::vector<double> samples = {1.0, 2.0};
  RecordSource src(samples, 1000.0);
  double a = 0.0;
  EXPECT_TRUE(src.next(&a));
  EXPECT_TRUE(src.next(&a));
  EXPECT_EQ(a, 2.0);
  EXPECT_FALSE(src.next(&a));
  EXPECT_THROW(RecordSource(samples, 0.0), std::invalid_argument);
}

}  // namespace
