#include "sim_host/run/damage.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sim_host/engines/build_engine.hpp"

namespace vines::host {

std::size_t damage_sample(double time_s, double rate_hz) {
  // A time on a sample (12.5 s at 1 kHz) is that sample, not the next one
  // by a rounding of time_s * rate_hz.
  const double k = std::ceil(time_s * rate_hz - 1e-9 * std::max(1.0, time_s * rate_hz));
  return k > 0 ? static_cast<std::size_t>(k) : 0;
}

void check_damage_scalar(const DamageSpec& damage, Scalar scalar, const std::string& what) {
  if (damage.any() && scalar == Scalar::kFixed)
    throw std::runtime_error(what + ": [damage]: a change of model mid-run is not available in fixed point "
                             "(loop.scalar = \"fixed\"): run the scene in double or float");
}

DamagedRun::DamagedRun(const SceneParams& p, const DamageSpec& damage, Scalar scalar, double rate_hz,
                       const std::string& what)
    : what_(what) {
  before_ = build_engine(p, scalar, what);
  if (!damage.any()) return;
  check_damage_scalar(damage, scalar, what);
  after_ = build_engine(damaged_params(p, damage), scalar, what + " (damaged at damage.time_s)");
  switch_k_ = damage_sample(damage.time_s, rate_hz);
}

void DamagedRun::maybe_switch() {
  if (!after_ || switched_ || k_ != switch_k_) return;
  const std::string why = after_->take_over(*before_);
  if (!why.empty()) throw std::runtime_error(what_ + ": damage.time_s: " + why);
  switched_ = true;
}

void DamagedRun::init(double a0) {
  before_->init(a0);
  k_ = 0;
  switched_ = false;
  maybe_switch();
}

void DamagedRun::run(const double* a, std::size_t n) {
  while (n > 0) {
    std::size_t m = n;
    if (after_ && !switched_) m = std::min(n, switch_k_ - k_);
    engine().run(a, m);
    a += m;
    n -= m;
    k_ += m;
    maybe_switch();
  }
}

}  // namespace vines::host
