// Host HAL backend: a record resampled to the sensor rate, and the sample
// source that feeds it (with a simulated clock) to every host run.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "host/record.hpp"
#include "host/record_error.hpp"

namespace vines::hal {
namespace {

using detail::fail;
using detail::fmt;

constexpr double kKnotSnap = 1e-9;                // a knot if |u - round(u)| is below (u in dt)
constexpr long long kMaxResampled = 100'000'000;  // refuse absurd resampling requests

}  // namespace

// ---- resample: piecewise-linear through the knots, exact at the knots ----

std::vector<double> resample(const Record& record, double rate_hz) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    fail(record.path, "resample rate must be positive, got " + fmt(rate_hz));
  }
  if (!(record.dt_s > 0.0) || !std::isfinite(record.dt_s) || !std::isfinite(record.t0_s)) {
    fail(record.path, "record has no valid dt/t0");
  }

  // Knots a[0..N-1] at t0 + i dt, then a = 0 at t0 + N dt and after; 0 before t0.
  const std::vector<double>& a = record.accel_mps2;
  const long long n = static_cast<long long>(a.size());
  const double end_s = record.t0_s + record.duration_s();
  if (!(end_s * rate_hz < static_cast<double>(kMaxResampled))) {
    fail(record.path, "resampling to " + fmt(rate_hz) + " Hz gives too many samples");
  }
  const long long k_last = std::max(0LL, std::llround(end_s * rate_hz));
  auto knot = [&](long long i) { return (i >= 0 && i < n) ? a[static_cast<std::size_t>(i)] : 0.0; };

  std::vector<double> out(static_cast<std::size_t>(k_last) + 1);
  for (long long k = 0; k <= k_last; ++k) {
    const double t = static_cast<double>(k) / rate_hz;
    const double u = (t - record.t0_s) / record.dt_s;  // position in knot units
    const double nearest = std::round(u);
    double v = 0.0;
    if (std::abs(u - nearest) <= kKnotSnap) {
      v = knot(static_cast<long long>(nearest));  // on a knot: the sample itself, bit for bit
    } else if (u > 0.0 && u < static_cast<double>(n)) {
      const long long i = static_cast<long long>(std::floor(u));
      const double frac = u - static_cast<double>(i);
      v = knot(i) + frac * (knot(i + 1) - knot(i));
    }
    out[static_cast<std::size_t>(k)] = v;
  }
  return out;
}

// ---- RecordSource: samples in order; the clock reads round(k * 1e9 / rate) at sample k ----

RecordSource::RecordSource(const double* samples_mps2, std::size_t n, double rate_hz, SimClock* clock)
    : samples_(samples_mps2), n_(n), rate_hz_(rate_hz), clock_(clock) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    throw std::invalid_argument("RecordSource: rate must be positive, got " + fmt(rate_hz));
  }
}

void RecordSource::advance_clock(std::size_t from, std::size_t to) {
  // By the difference of exact tick times, so rounding never accumulates.
  auto tick = [this](std::size_t k) {
    return static_cast<std::uint64_t>(std::llround(static_cast<double>(k) * 1e9 / rate_hz_));
  };
  if (clock_ != nullptr && to > from) clock_->advance_ns(tick(to) - tick(from));
}

bool RecordSource::next(double* accel_mps2) {
  if (pos_ >= n_) return false;
  if (pos_ > 0) advance_clock(pos_ - 1, pos_);
  *accel_mps2 = samples_[pos_++];
  return true;
}

std::size_t RecordSource::read(double* out, std::size_t n) {
  const std::size_t k = std::min(n, n_ - pos_);
  if (k == 0) return 0;
  std::copy(samples_ + pos_, samples_ + pos_ + k, out);
  advance_clock(pos_ == 0 ? 0 : pos_ - 1, pos_ + k - 1);  // the clock reads the last sample's time
  pos_ += k;
  return k;
}

}  // namespace vines::hal
