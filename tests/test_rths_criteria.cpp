// The vRTHS benchmark's criteria (sim_host/hil/modes/rths_criteria.hpp) on synthetic
// signals whose answers are known in closed form: a delayed copy gives its
// delay, a scaled copy its RMS and peak percentages, a zero reference no
// percentage at all.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <vector>

#include "sim_host/hil/modes/rths_criteria.hpp"

namespace vines::host::rths {
namespace {

constexpr double kH = 1e-3;

// f sampled every kH for n samples, shifted by `delay` seconds: f(k h - delay).
std::vector<double> sampled(const std::function<double(double)>& f, int n, double delay = 0) {
  std::vector<double> y(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) y[static_cast<std::size_t>(k)] = f(k * kH - delay);
  return y;
}

// A burst of duration T: f(t) times a Hann window over [0, T], at rest at
// both ends (as a hybrid test starts and ends).
std::function<double(double)> burst(std::function<double(double)> f, double T) {
  return [f, T](double t) { return t <= 0 || t >= T ? 0.0 : f(t) * 0.5 * (1 - std::cos(2 * M_PI * t / T)); };
}

// Three incommensurate sines.
double broadband(double t) {
  return std::sin(2 * M_PI * 1.3 * t) + 0.6 * std::sin(2 * M_PI * 3.7 * t + 1) + 0.3 * std::sin(2 * M_PI * 7.1 * t);
}

// A 2 Hz sine burst delayed by 3.4 samples, and a broadband burst delayed by
// 17.25 or led by 2.6 samples: the delay comes back within 0.01 sample.
TEST(RthsCriteria, DelayOfADelayedCopyBelowOneSample) {
  const auto sine = burst([](double t) { return std::sin(2 * M_PI * 2.0 * t); }, 19.0);
  const auto d1 = tracking_delay_s(sampled(sine, 20000), sampled(sine, 20000, 3.4 * kH), kH);
  ASSERT_TRUE(d1);
  EXPECT_NEAR(*d1, 3.4e-3, 1e-5);
  const auto bb = burst(broadband, 29.0);
  for (double samples : {17.25, -2.6, 0.0}) {
    const auto d = tracking_delay_s(sampled(bb, 30000), sampled(bb, 30000, samples * kH), kH);
    ASSERT_TRUE(d) << samples;
    EXPECT_NEAR(*d, samples * kH, 1e-5) << samples;
  }
}

// A delay beyond the search (150 ms against +-100 ms) is not reported as the
// search's edge; a wider search finds it.
TEST(RthsCriteria, DelayBeyondTheSearchIsNotReported) {
  const auto bb = burst(broadband, 29.0);
  const std::vector<double> x = sampled(bb, 30000), y = sampled(bb, 30000, 0.150);
  EXPECT_FALSE(tracking_delay_s(x, y, kH, 0.1));
  const auto d = tracking_delay_s(x, y, kH, 0.2);
  ASSERT_TRUE(d);
  EXPECT_NEAR(*d, 0.150, 1e-5);
}

// measured = 1.03 target: RMS and peak errors are 3 %; a copy with an offset
// of 0.1 on a unit sine: RMS 100 * 0.1 / (1 / sqrt 2), peak 10 %.
TEST(RthsCriteria, ScaledAndOffsetCopiesGiveTheirPercentages) {
  auto sine = [](double t) { return std::sin(2 * M_PI * 1.0 * t); };
  const std::vector<double> ref = sampled(sine, 10000);  // ten whole periods
  std::vector<double> scaled = ref, offset = ref;
  for (double& v : scaled) v *= 1.03;
  for (double& v : offset) v += 0.1;
  EXPECT_NEAR(*rms_error_pct(ref, scaled), 3.0, 1e-9);
  EXPECT_NEAR(*peak_error_pct(ref, scaled), 3.0, 1e-9);
  EXPECT_NEAR(*rms_error_pct(ref, offset), 100 * 0.1 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(*peak_error_pct(ref, offset), 10.0, 1e-9);
  EXPECT_EQ(*rms_error_pct(ref, ref), 0.0);
}

// A zero reference has no scale: no percentage, no delay (not a division by
// zero); mismatched or too short signals are refused.
TEST(RthsCriteria, ZeroReferenceAndBadInputs) {
  const std::vector<double> zero(100, 0.0), one(100, 1.0);
  EXPECT_FALSE(rms_error_pct(zero, one));
  EXPECT_FALSE(peak_error_pct(zero, one));
  EXPECT_FALSE(tracking_delay_s(zero, one, kH));
  EXPECT_FALSE(tracking_delay_s(one, zero, kH));
  EXPECT_THROW(rms_error_pct(one, std::vector<double>(99, 1.0)), std::invalid_argument);
  EXPECT_THROW(peak_error_pct({}, {}), std::invalid_argument);
  EXPECT_THROW(tracking_delay_s(one, one, 0.0), std::invalid_argument);
  EXPECT_THROW(tracking_delay_s(one, one, kH, 0.5e-3), std::invalid_argument);
  EXPECT_THROW(tracking_delay_s({1, 2}, {1, 2}, kH), std::invalid_argument);
}

}  // namespace
}  // namespace vines::host::rths
