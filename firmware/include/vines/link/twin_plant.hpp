// The plant of a twin node with an estimator (link/node.hpp's Plant, twin
// mode, estimator kalman): the estimator of twin/estimator.hpp on the twin
// image the bench designed, its outputs as telemetry. It is the whole plant
// of the boards' twin image (firmware/app/twin_main.cpp: a monitoring node
// holds no simulation model, whatever the building's device) and the host's
// in that mode (sim_host/hil/modes/plant.cpp), so the same code runs on either.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "vines/link/config.hpp"
#include "vines/link/messages.hpp"
#include "vines/twin/estimator.hpp"

namespace vines::link {

template <typename S, int N>
class TwinPlant {
 public:
  const char* image_begin(std::uint32_t /*total*/ = 0) {
    est_.image_begin();
    return nullptr;
  }
  const char* image_push(const std::uint8_t* p, std::size_t n) { return est_.image_push(p, n); }
  const char* image_finish() { return est_.image_finish(); }

  // Twin mode with the estimator only; the settings must fit the image.
  bool configure(const NodeConfig& c, char* msg, std::size_t cap) {
    const char* why = c.mode != NodeMode::kTwin || c.estimator != TwinEstimator::kKalman
                          ? "mode: this node runs the twin estimator only (--mode twin --estimator kalman)"
                          : check(c);
    if (why && cap > 0) {
      std::size_t i = 0;
      for (; why[i] != '\0' && i + 1 < cap; ++i) msg[i] = why[i];
      msg[i] = '\0';
    }
    return why == nullptr;
  }

  // The settings must fit the twin image held: nullptr, or why not.
  const char* check(const NodeConfig& c) const {
    if (!est_.ready()) return "estimator kalman: send a twin image before the settings";
    if (c.scene.frame.stories != est_.dims().stories) return "frame.stories: differs from the twin image's";
    if (!(std::fabs(est_.period() * c.scene.loop.sensor_rate_hz - 1.0) <= 1e-12))
      return "loop.sensor_rate_hz: differs from the twin image's";
    return nullptr;
  }

  void sense(const double* y, int ny) { y_ = y, ny_ = ny; }
  void init(double a0, double /*f0*/ = 0) {
    est_.init(static_cast<S>(a0), y_, ny_);
    turn_ = 0;
  }
  void step(double a1, double /*f1*/ = 0) { est_.step(static_cast<S>(a1), y_, ny_); }

  // The estimated floors, top-floor acceleration and device force (on its
  // floor, N); one spring's factor and sd in turn; the alarms.
  void read(Telemetry* t) {
    const int n = est_.dims().stories, np = est_.dims().np;
    t->n = static_cast<std::uint8_t>(n);
    for (int i = 0; i < n; ++i) t->x[i] = static_cast<double>(est_.x(i));
    t->acc_top = static_cast<double>(est_.acc_top());
    t->contact_force = static_cast<double>(est_.force());
    const int j = turn_;
    turn_ = turn_ + 1 < np ? turn_ + 1 : 0;
    t->est_index = static_cast<std::uint8_t>(j);
    t->est_eta = 1.0 - static_cast<double>(est_.loss(j));
    t->est_sd = static_cast<double>(est_.loss_sd(j));
    t->est_stat = j < n ? static_cast<double>(est_.evidence(j)) : 0.0;
    t->stat_threshold = static_cast<double>(est_.evidence_threshold());
    t->alarm_story = static_cast<std::uint8_t>(est_.alarm_story());
    t->second_story = static_cast<std::uint8_t>(est_.second_story());
    t->damage_size = static_cast<double>(est_.damage_size());
    t->second_size = static_cast<double>(est_.second_size());
    t->change_score = static_cast<double>(est_.change_score());
    t->onset_s = est_.onset_step() < 0 ? -1.0 : static_cast<double>(est_.onset_step()) * est_.period();
    if (est_.detected()) t->flags |= kDamage;
    if (est_.device_alarm()) t->flags |= kDeviceAlarm;
    if (est_.impact()) t->flags |= kImpact;
  }

 private:
  twin::Estimator<S, N> est_;
  const double* y_ = nullptr;
  int ny_ = 0;
  int turn_ = 0;
};

}  // namespace vines::link
