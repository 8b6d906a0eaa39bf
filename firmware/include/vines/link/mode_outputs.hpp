// What the node adds to a step's telemetry in its modes (link/node.hpp):
// twin, the residual of the measured top-floor acceleration, its running
// RMS and the drift alarms; hybrid, the table command from the top floor
// (itself, extrapolated over the delay, or the adaptive compensator's).
// Fixed memory; reset at each START.
#pragma once

#include <cmath>
#include <cstdint>

#include "vines/link/ats.hpp"
#include "vines/link/config.hpp"
#include "vines/link/extrapolate.hpp"
#include "vines/link/messages.hpp"

namespace vines::link {

class ModeOutputs {
 public:
  void reset(const NodeConfig& cfg, double h) {
    ms_residual_ = 0;
    hist_n_ = 0;
    ats_.reset(h, cfg.comp_window_s, cfg.comp_delay_s);
  }

  // Twin: the residual of the measured top-floor acceleration (have: it was
  // measured), its running RMS (a VI NES impact's samples left out: the
  // estimator has no model of the impact, and its residual there is not the
  // model's error), and the drift alarms.
  void twin(const NodeConfig& cfg, double h, Telemetry* t, double measured, bool have) {
    t->aux = have ? measured - t->acc_top : 0.0;
    if (have && !(t->flags & kImpact)) ms_residual_ += (t->aux * t->aux - ms_residual_) * std::fmin(1.0, h / cfg.residual_window_s);
    if (cfg.residual_limit_mps2 > 0 && std::sqrt(ms_residual_) > cfg.residual_limit_mps2) t->flags |= kResidualAlarm;
    for (int i = 0; i < t->n; ++i) {
      const double drift = t->x[i] - (i ? t->x[i - 1] : 0.0);
      if (cfg.drift_limit_m[i] > 0 && !(std::fabs(drift) <= cfg.drift_limit_m[i])) {
        t->drift_alarms |= std::uint64_t{1} << i;
        t->flags |= kDriftAlarm;
      }
    }
  }

  // Hybrid: the table command from the top floor: itself (none), extrapolated
  // over the delay (polynomial), or the adaptive compensator's, fed the
  // measured table xm too (its coefficients into the telemetry).
  double command(const NodeConfig& cfg, double h, double x_top, double xm, Telemetry* t) {
    if (cfg.comp_kind == CompKind::kNone) return x_top;
    if (cfg.comp_kind == CompKind::kAdaptive) {
      const double u = ats_.step(x_top, xm);
      for (int i = 0; i < 3; ++i) t->comp[i] = ats_.coefficient(i);
      return u;
    }
    for (int i = 3; i > 0; --i) hist_[i] = hist_[i - 1];
    hist_[0] = x_top;
    if (hist_n_ < 4) ++hist_n_;
    const int p = cfg.comp_order < hist_n_ - 1 ? cfg.comp_order : hist_n_ - 1;
    return extrapolate(hist_, p, cfg.comp_delay_s, h);
  }

 private:
  double ms_residual_ = 0;
  double hist_[4] = {};
  int hist_n_ = 0;
  Ats ats_;
};

}  // namespace vines::link
