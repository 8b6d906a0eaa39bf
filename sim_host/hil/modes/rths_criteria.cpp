#include "sim_host/hil/modes/rths_criteria.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vines::host::rths {
namespace {

// Two signals of the same, non-zero length.
void check_pair(const std::vector<double>& a, const std::vector<double>& b, std::size_t min_len, const char* what) {
  if (a.size() != b.size())
    throw std::invalid_argument(std::string(what) + ": signals of different lengths (" + std::to_string(a.size()) +
                                " and " + std::to_string(b.size()) + " samples)");
  if (a.size() < min_len)
    throw std::invalid_argument(std::string(what) + ": needs at least " + std::to_string(min_len) + " samples, got " +
                                std::to_string(a.size()));
}

// The sum of target[k] * measured[k + lag], both zero outside the run
// (unscaled: for signals at rest at both ends it is the full correlation,
// symmetric about the delay; a mean over the overlap would pull the peak
// away from zero lag by about 1/(N w^2 h^2) samples at frequency w).
double correlation(const std::vector<double>& target, const std::vector<double>& measured, long lag) {
  const long n = static_cast<long>(target.size());
  const long k0 = std::max(0L, -lag), k1 = std::min(n, n - lag);
  double s = 0;
  for (long k = k0; k < k1; ++k) s += target[static_cast<std::size_t>(k)] * measured[static_cast<std::size_t>(k + lag)];
  return s;
}

bool all_zero(const std::vector<double>& x) {
  return std::all_of(x.begin(), x.end(), [](double v) { return v == 0.0; });
}

}  // namespace

std::optional<double> tracking_delay_s(const std::vector<double>& target, const std::vector<double>& measured,
                                       double h, double max_lag_s) {
  check_pair(target, measured, 3, "tracking delay");
  if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("tracking delay: the sample period must be > 0");
  const double lags = max_lag_s / h;
  if (!(lags >= 1)) throw std::invalid_argument("tracking delay: the search must span at least one sample each way");
  if (all_zero(target) || all_zero(measured)) return std::nullopt;
  // The peak of the cross-correlation over +-max_lag (but within the signals).
  const long m = std::min(static_cast<long>(lags), static_cast<long>(target.size()) - 2);
  long best = -m;
  double peak = correlation(target, measured, -m);
  for (long lag = -m + 1; lag <= m; ++lag) {
    const double r = correlation(target, measured, lag);
    if (r > peak) peak = r, best = lag;
  }
  if (best == -m || best == m) return std::nullopt;  // on the edge: beyond the search
  // The vertex of the parabola through the peak and its neighbours.
  const double rm = correlation(target, measured, best - 1), rp = correlation(target, measured, best + 1);
  const double curv = rm - 2 * peak + rp;
  const double shift = curv < 0 ? 0.5 * (rm - rp) / curv : 0.0;
  return (static_cast<double>(best) + shift) * h;
}

std::optional<double> rms_error_pct(const std::vector<double>& reference, const std::vector<double>& test) {
  check_pair(reference, test, 1, "RMS error");
  double se = 0, sr = 0;
  for (std::size_t k = 0; k < reference.size(); ++k) {
    const double e = test[k] - reference[k];
    se += e * e, sr += reference[k] * reference[k];
  }
  if (!(sr > 0)) return std::nullopt;
  return 100 * std::sqrt(se / sr);
}

std::optional<double> peak_error_pct(const std::vector<double>& reference, const std::vector<double>& test) {
  check_pair(reference, test, 1, "peak error");
  double pe = 0, pr = 0;
  for (std::size_t k = 0; k < reference.size(); ++k)
    pe = std::max(pe, std::fabs(test[k] - reference[k])), pr = std::max(pr, std::fabs(reference[k]));
  if (!(pr > 0)) return std::nullopt;
  return 100 * pe / pr;
}

}  // namespace vines::host::rths
