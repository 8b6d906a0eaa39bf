// A run whose building is damaged mid-record (a scene's [damage]): drive()'s
// target that steps the scene's model up to the sample at damage.time_s,
// then hands the run to the damaged model (Engine::take_over: the same
// floors, device, clock, peaks, counters, ledger) and steps that one. Without
// damage (no [damage], or every factor 1) it is the one engine, bit for bit.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "sim_host/engines/engine.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {

class DamagedRun {
 public:
  // The models of `p` (the scene's parameters, or its bare frame's) and,
  // when `damage` changes a story, of damaged_params(p, damage), in
  // `scalar`; the switch at the first sample at or after damage.time_s
  // (samples at `rate_hz`). Throws EngineError / std::runtime_error naming
  // `what` (fixed point with damage is refused).
  DamagedRun(const SceneParams& p, const DamageSpec& damage, Scalar scalar, double rate_hz, const std::string& what);

  void init(double a0);
  void run(const double* a, std::size_t n);

  // The engine stepping now (the damaged one after the switch).
  Engine& engine() { return after_ && switched_ ? *after_ : *before_; }
  const Engine& engine() const { return after_ && switched_ ? *after_ : *before_; }
  // The undamaged model's engine (its info() is the scene's frame).
  const Engine& undamaged() const { return *before_; }
  // The damaged model's engine, or nullptr when the damage changes nothing.
  const Engine* damaged() const { return after_.get(); }
  bool switched() const { return switched_; }
  std::size_t switch_sample() const { return switch_k_; }

 private:
  void maybe_switch();

  std::unique_ptr<Engine> before_, after_;
  std::size_t switch_k_ = 0, k_ = 0;
  bool switched_ = false;
  std::string what_;
};

// The sample at which damage at time_s strikes: the first at or after it.
std::size_t damage_sample(double time_s, double rate_hz);

// Refuses (std::runtime_error naming `what`) damage that changes a story in
// a scalar with no change of model mid-run (fixed point).
void check_damage_scalar(const DamageSpec& damage, Scalar scalar, const std::string& what);

}  // namespace vines::host
