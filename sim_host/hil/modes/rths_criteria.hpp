// The evaluation criteria of the virtual real-time hybrid simulation (vRTHS)
// benchmark (Silva, Gomez, Maghareh, Dyke, Spencer, MSSP 135, 2020), as pure
// functions on uniformly sampled signals: the tracking delay of the measured
// table displacement behind its target (peak of their cross-correlation,
// refined below one sample), and normalised RMS and peak errors in percent
// (tracking: measured against target; response: hybrid against the pure
// simulation). Formulas in docs/rths_criteria.md.
#pragma once

#include <optional>
#include <vector>

namespace vines::host::rths {

// Delay [s] of `measured` behind `target` (positive: measured lags), both
// sampled every h: the lag L in [-max_lag, max_lag] maximising the sum of
// target[k] * measured[k + L] (zero outside the run), refined by the parabola
// through the three lags around the peak. None when either signal is zero
// throughout or the peak lies on the edge of the search (the delay is then
// beyond max_lag). Throws std::invalid_argument for signals of different
// lengths, shorter than 3 samples, h <= 0 or max_lag < 1 sample.
std::optional<double> tracking_delay_s(const std::vector<double>& target, const std::vector<double>& measured,
                                       double h, double max_lag_s = 0.1);

// 100 RMS(test - reference) / RMS(reference). None when the reference is zero
// throughout (no scale to judge against). Throws std::invalid_argument for
// signals of different lengths or empty ones.
std::optional<double> rms_error_pct(const std::vector<double>& reference, const std::vector<double>& test);

// 100 max|test - reference| / max|reference|; none for a zero reference.
// Throws as rms_error_pct.
std::optional<double> peak_error_pct(const std::vector<double>& reference, const std::vector<double>& test);

}  // namespace vines::host::rths
