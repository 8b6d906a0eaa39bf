// Internals shared by the reference and CVODE integrators: the ground input,
// the bookkeeping of peaks and contacts, what an event does (the firmware's
// contact-mode state machine), the integrators.
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include "sim_host/reference/ode.hpp"
#include "sim_host/reference/spec.hpp"
#include "sim_host/reference/truth.hpp"
#include "vines/model/contact_mode.hpp"

namespace vines::host::reference {

// Ground acceleration linear between samples; interval k is [k, k + 1] / rate,
// the last one cut at t_end.
struct Ground {
  const std::vector<double>* samples = nullptr;
  double rate_hz = 0;
  int intervals = 0;
  double t_end = 0;
};

// Peaks, contacts and overlaps as the integrators report them (double).
struct Tally {
  Result r;
  double depth = 0;     // deepest overlap of the current contact
  double start_s = 0;   // when it started
  void peak(double x_abs, double t) {
    if (x_abs > r.peak_top) r.peak_top = x_abs, r.t_peak_top = t;
  }
  void begin_contact(double t) { depth = 0, start_s = t; }
  void overlap(double d) {
    depth = std::fmax(depth, d);
    r.max_overlap = std::fmax(r.max_overlap, d);
  }
  // A finite-duration contact ends: counted if deeper than the counting depth.
  void end_contact(double count_depth) {
    if (depth > count_depth) ++r.contacts, r.contact_start_s.push_back(start_s);
  }
  // An instantaneous impact: counted unless it is a plastic landing at rest.
  void impact(double t, double v_app) {
    if (v_app > kStickSpeed) ++r.contacts, r.contact_start_s.push_back(t);
  }
};

// What the contact-mode transitions (contact_mode.hpp) do in the drivers
// at an event at time t on the state y: Newton's impact law applied and
// tallied, a contact's start and end tallied.
template <typename T>
struct EventActs {
  const SceneOde<T>& ode;
  T* y;
  Tally& tally;
  double t;

  Impact impact(int side) {
    const T v_app = ode.overlap_rate(y, side);
    if (!(v_app > T(0))) return Impact::kNone;
    const bool plastic = ode.impact(y, side, v_app);
    tally.impact(t, static_cast<double>(v_app));
    return plastic ? Impact::kPlastic : Impact::kRebound;
  }
  // Riding wall `side`, the wall would have to pull.
  bool pulls(int side) const { return (side < 0 ? -ode.holding_force(y) : ode.holding_force(y)) > T(0); }
  void begin_contact(int) { tally.begin_contact(t); }
  bool end_contact() {
    tally.end_contact(ode.spec().count_depth);
    return true;
  }
};

// The transition at an event on wall `side` (-1, +1) from the driver's mode;
// false if there was none after all (an impact without approach).
template <typename T>
bool take_event(Mode& mode, int side, const SceneOde<T>& ode, T* y, Tally& tally, double t) {
  EventActs<T> act{ode, y, tally, t};
  return vines::take_event(mode, side, ode.restitution(), act);
}

// The walls whose event can come next in `mode`: both in free flight, the
// one in contact or ridden; returns how many (into out).
inline int event_walls(Mode mode, int out[2]) {
  switch (mode) {
    case Mode::kFree: out[0] = -1, out[1] = 1; return 2;
    case Mode::kContactLeft: case Mode::kStuckLeft: out[0] = -1; return 1;
    default: out[0] = 1; return 1;
  }
}

// DOP853 with event location in scalar T (long double: the reference;
// double: the `dop853-driver` baseline); instantiated for those two.
template <typename T>
Result integrate_dop853(const OdeSpec& spec, const Ground& g, double rtol);
// The tuned DOP853 in double (dop853_tuned.cpp): events on the dense output.
Result integrate_dop853_tuned(const OdeSpec& spec, const Ground& g, double rtol);
Result integrate_cvode(const OdeSpec& spec, const Ground& g, double rtol, bool bdf);

// Stationary points in (0, 1) of the cubic Hermite interpolant on a step of
// size h with values g0, g1 and slopes d0, d1; returns how many (0..2).
template <typename T>
int hermite_stationary(T g0, T d0, T g1, T d1, T h, T theta[2]) {
  const T a = T(6) * (g0 - g1) + T(3) * h * (d0 + d1);
  const T b = T(6) * (g1 - g0) - h * (T(4) * d0 + T(2) * d1);
  const T c = h * d0;
  int n = 0;
  auto keep = [&](T t) {
    if (t > T(0) && t < T(1)) theta[n++] = t;
  };
  using std::fabs;
  using std::sqrt;
  if (fabs(a) <= T(1e-12) * (fabs(b) + fabs(c))) {
    if (b != T(0)) keep(-c / b);
    return n;
  }
  const T disc = b * b - T(4) * a * c;
  if (disc < T(0)) return 0;
  const T q = -T(0.5) * (b + (b < T(0) ? -sqrt(disc) : sqrt(disc)));
  if (q != T(0)) keep(c / q);
  keep(q / a);
  if (n == 2 && theta[0] > theta[1]) std::swap(theta[0], theta[1]);
  return n;
}

// Value at theta of that interpolant.
template <typename T>
T hermite_value(T g0, T d0, T g1, T d1, T h, T t) {
  const T t2 = t * t, t3 = t2 * t;
  return (T(2) * t3 - T(3) * t2 + T(1)) * g0 + (t3 - T(2) * t2 + t) * h * d0 + (T(3) * t2 - T(2) * t3) * g1 +
         (t3 - t2) * h * d1;
}

}  // namespace vines::host::reference
