// The DOP853 driver, templated on the scalar: long double for the reference
// (`vines reference`), double for the `dop853` baseline of `vines bench`.
// DOP853 over each sample interval (a_g is linear inside, kinked at the
// samples), events located by re-taking the step from its start with an
// Illinois-secant step length, to a bracket of a few ulps of the time.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/reference/dop853.hpp"
#include "sim_host/reference/integrators.hpp"
#include "sim_host/reference/ode.hpp"

namespace vines::host::reference {
namespace {

template <typename T>
using State = std::vector<T>;

// Two states bracketing a located root: g <= 0 at lo, g > 0 at hi (step
// lengths from the current step start).
template <typename T>
struct Bracket {
  T lo = 0, hi = 0;
  State<T> ylo, flo, yhi, fhi;
  T err_hi = 0;  // error norm of the re-step to hi
};

template <typename T>
class ReferenceRun {
 public:
  using State = reference::State<T>;
  using Bracket = reference::Bracket<T>;
  ReferenceRun(const OdeSpec& spec, const Ground& g, T rtol)
      : ode_(spec), g_(g), rk_(ode_.size()), rtol_(rtol), atol_(ode_.scales()),
        y_(static_cast<std::size_t>(ode_.size())), f_(y_), y1_(y_), f1_(y_), tmp_(y_), ftmp_(y_) {
    for (T& a : atol_) a *= rtol_;
  }

  Result run() {
    ode_.initial_state(y_.data());
    tally_.peak(0.0, 0.0);
    const std::vector<double>& a = *g_.samples;
    const T rate = T(g_.rate_hz);
    T hprop = std::min(T(1e-3), T(1) / rate);
    for (int k = 0; k < g_.intervals; ++k) {
      t0_ = T(k) / rate;
      const T len = k + 1 == g_.intervals ? T(g_.t_end) - t0_ : T(1) / rate;
      a0_ = T(a[static_cast<std::size_t>(k)]);
      slope_ = (T(a[static_cast<std::size_t>(k) + 1]) - a0_) * rate;
      s0_ = 0;
      eval(s0_, y_.data(), f_.data());
      while (s0_ < len) hprop = advance(len, hprop);
    }
    tally_.r.elastic_energy = static_cast<double>(y_[static_cast<std::size_t>(ode_.energy_index())]);
    return tally_.r;
  }

 private:
  void eval(T s, const T* y, T* dy) {
    ++tally_.r.rhs_evals;
    ode_.rhs(a0_ + slope_ * s, y, dy, mode_);
  }
  // The step from the current start (s0_, y_, f_) of length tau.
  T restep(T tau, T* out, T* fout) {
    auto rhs = [this](T s, const T* y, T* dy) { eval(s, y, dy); };
    return rk_.step(rhs, s0_, y_.data(), f_.data(), tau, rtol_, atol_.data(), out, fout);
  }
  double time(T s) const { return static_cast<double>(t0_ + s); }

  // ---- mode events: g crosses zero upwards ----
  // Candidates: both walls in free flight, the wall in contact or riding.
  int candidates(int out[2]) const { return ode_.has_particle() ? event_walls(mode_, out) : 0; }
  // Free: overlap beyond the start depth; contact: overlap back to 0;
  // riding: the wall would have to pull.
  T event_g(const T* y, int side) const {
    switch (mode_) {
      case Mode::kFree: return ode_.overlap(y, side) - ode_.start_depth();
      case Mode::kContactLeft: case Mode::kContactRight: return -ode_.overlap(y, side);
      default: return side < 0 ? -ode_.holding_force(y) : ode_.holding_force(y);
    }
  }
  // Its slope (NaN when it has none at hand: riding).
  T event_slope(const T* y, int side) const {
    switch (mode_) {
      case Mode::kFree: return ode_.overlap_rate(y, side);
      case Mode::kContactLeft: case Mode::kContactRight: return -ode_.overlap_rate(y, side);
      default: return std::numeric_limits<T>::quiet_NaN();
    }
  }

  // Illinois on the step length for a root of g(y, f) in (b.lo, b.hi], with
  // g <= 0 at lo and g > 0 at hi, down to a few ulps of the time.
  template <class G>
  Bracket locate(G g, Bracket b) {
    T glo = g(b.ylo.data(), b.flo.data()), ghi = g(b.yhi.data(), b.fhi.data());
    int last = 0;
    T width = b.hi - b.lo;
    for (int it = 0; it < 300; ++it) {
      if (b.hi - b.lo <= T(16) * std::numeric_limits<T>::epsilon() * (t0_ + s0_ + b.hi)) break;
      T x = (b.lo * ghi - b.hi * glo) / (ghi - glo);
      // Bisect when the secant leaves the bracket or the bracket stalls.
      const bool stalled = it % 4 == 3 && b.hi - b.lo > T(0.5) * width;
      if (it % 4 == 3) width = b.hi - b.lo;
      if (!(x > b.lo && x < b.hi) || stalled) x = T(0.5) * (b.lo + b.hi);
      const T err = restep(x, tmp_.data(), ftmp_.data());
      const T gx = g(tmp_.data(), ftmp_.data());
      if (gx > T(0)) {
        b.hi = x, ghi = gx, b.yhi = tmp_, b.fhi = ftmp_, b.err_hi = err;
        if (last == 1) glo *= T(0.5);
        last = 1;
      } else {
        b.lo = x, glo = gx, b.ylo = tmp_, b.flo = ftmp_;
        if (last == -1) ghi *= T(0.5);
        last = -1;
      }
    }
    ++tally_.r.events;
    return b;
  }
  Bracket from_start(T hi, const State& yhi, const State& fhi, T err_hi) const {
    return Bracket{0, hi, y_, f_, yhi, fhi, err_hi};
  }

  // ---- monitors inside an accepted step: peak of |x_top|, deepest overlap ----
  // Every sign change of g over the step [0, len] (ends, or two hidden in
  // the step when the Hermite interpolant with slopes d turns back across 0).
  template <class G, class D, class On>
  void roots_of(G g, D d, T len, const State& ye, const State& fe, On on_root) {
    const T g0 = g(y_.data(), f_.data()), g1 = g(ye.data(), fe.data());
    auto root_in = [&](Bracket b) {
      const T sign = g(b.yhi.data(), b.fhi.data()) > g(b.ylo.data(), b.flo.data()) ? T(1) : T(-1);
      on_root(locate([&](const T* y, const T* f) { return sign * g(y, f); }, std::move(b)));
    };
    if ((g0 < T(0)) != (g1 < T(0))) {
      root_in(from_start(len, ye, fe, T(0)));
      return;
    }
    const T d0 = d(y_.data(), f_.data()), d1 = d(ye.data(), fe.data());
    T th[2];
    const int n = hermite_stationary(g0, d0, g1, d1, len, th);
    for (int i = 0; i < n; ++i) {
      if ((hermite_value(g0, d0, g1, d1, len, th[i]) < T(0)) == (g0 < T(0))) continue;
      State ym(y_.size()), fm(y_.size());
      restep(th[i] * len, ym.data(), fm.data());
      if ((g(ym.data(), fm.data()) < T(0)) == (g0 < T(0))) continue;
      root_in(from_start(th[i] * len, ym, fm, T(0)));
      root_in(Bracket{th[i] * len, len, ym, fm, ye, fe, T(0)});
      return;
    }
  }
  void monitor(T len, const State& ye, const State& fe) {
    const int vtop = ode_.size() / 2 + ode_.floors() - 1;  // index of v_top
    tally_.peak(static_cast<double>(std::fabs(ode_.top_x(ye.data()))), time(s0_ + len));
    roots_of([vtop](const T* y, const T*) { return y[vtop]; },
             [vtop](const T*, const T* f) { return f[vtop]; }, len, ye, fe, [this](const Bracket& b) {
               const T xl = std::fabs(ode_.top_x(b.ylo.data())), xh = std::fabs(ode_.top_x(b.yhi.data()));
               tally_.peak(static_cast<double>(std::max(xl, xh)), time(s0_ + (xl > xh ? b.lo : b.hi)));
             });
    if (!in_contact(mode_)) return;
    const int side = mode_ == Mode::kContactLeft ? -1 : 1;
    const int p = ode_.size() / 2, fl = ode_.spec().floor, n = ode_.floors();
    tally_.overlap(static_cast<double>(ode_.overlap(ye.data(), side)));
    roots_of([this, side](const T* y, const T*) { return ode_.overlap_rate(y, side); },
             [=](const T*, const T* f) { return side < 0 ? f[p + fl] - f[p + n] : f[p + n] - f[p + fl]; }, len,
             ye, fe, [this, side](const Bracket& b) {
               tally_.overlap(static_cast<double>(
                   std::max(ode_.overlap(b.ylo.data(), side), ode_.overlap(b.yhi.data(), side))));
             });
  }

  // ---- what an event does: the firmware's contact-mode transition ----
  void apply(int side) { take_event(mode_, side, ode_, y_.data(), tally_, time(s0_)); }

  // An event due before any time passes (the state already beyond a surface,
  // and approaching it in free flight): 0 if none, else the wall side.
  int due() const {
    int c[2];
    const int n = candidates(c);
    for (int i = 0; i < n; ++i)
      if (event_g(y_.data(), c[i]) > T(0) && (mode_ != Mode::kFree || ode_.overlap_rate(y_.data(), c[i]) > T(0)))
        return c[i];
    return 0;
  }

  // One attempted step inside the interval of length len; returns the next
  // proposed step size.
  T advance(T len, T hprop) {
    if (!fresh_) {
      if (const int side = due()) {
        ++tally_.r.events;
        apply(side);
        eval(s0_, y_.data(), f_.data());
        fresh_ = true;
        return hprop;
      }
    }
    const bool to_end = hprop >= len - s0_;
    const T h = to_end ? len - s0_ : hprop;
    if (!(h > T(1e-6) * std::numeric_limits<T>::epsilon() * len))
      throw std::runtime_error("reference: step size underflow at t = " + std::to_string(time(s0_)) + " s");
    const T err = restep(h, y1_.data(), f1_.data());
    auto factor = [](T e) { return e == T(0) ? T(10) : std::min(T(10), std::max(T(0.2), T(0.9) * std::pow(e, T(-0.125)))); };
    if (!(err <= T(1))) {
      ++tally_.r.rejected;
      return h * std::min(T(1), factor(err));
    }

    // The earliest mode event inside the step, if any.
    int c[2];
    const int nc = candidates(c);
    Bracket best;
    int best_side = 0;
    for (int i = 0; i < nc; ++i) {
      const int side = c[i];
      const T g0 = event_g(y_.data(), side), g1 = event_g(y1_.data(), side);
      if (g0 > T(0)) continue;
      auto gfun = [this, side](const T* y, const T*) { return event_g(y, side); };
      if (g1 > T(0)) {
        const Bracket b = locate(gfun, from_start(h, y1_, f1_, err));
        if (!best_side || b.hi < best.hi) best = b, best_side = side;
        continue;
      }
      // A graze: the interpolant of g rises above zero inside the step.
      const T d0 = event_slope(y_.data(), side), d1 = event_slope(y1_.data(), side);
      if (std::isnan(d0)) continue;
      T th[2];
      const int n = hermite_stationary(g0, d0, g1, d1, h, th);
      for (int j = 0; j < n; ++j) {
        if (!(hermite_value(g0, d0, g1, d1, h, th[j]) > T(-1e-3) * ode_.start_depth())) continue;
        State ym(y_.size()), fm(y_.size());
        const T em = restep(th[j] * h, ym.data(), fm.data());
        if (!(gfun(ym.data(), fm.data()) > T(0))) continue;
        const Bracket b = locate(gfun, from_start(th[j] * h, ym, fm, em));
        if (!best_side || b.hi < best.hi) best = b, best_side = side;
        break;
      }
    }
    if (best_side) {
      if (!(best.err_hi <= T(1))) {  // the step to the event is not accurate enough: shorter
        ++tally_.r.rejected;
        return best.hi * T(0.5);
      }
      monitor(best.hi, best.yhi, best.fhi);
      ++tally_.r.steps;
      s0_ += best.hi;
      y_ = best.yhi;
      apply(best_side);
      eval(s0_, y_.data(), f_.data());
      fresh_ = true;
      return hprop;
    }

    monitor(h, y1_, f1_);
    ++tally_.r.steps;
    s0_ = to_end ? len : s0_ + h;
    std::swap(y_, y1_);
    std::swap(f_, f1_);
    fresh_ = false;
    const T next = h * factor(err);
    return to_end ? std::max(next, hprop) : next;
  }

  SceneOde<T> ode_;
  Ground g_;
  Dop853<T> rk_;
  T rtol_;
  State atol_;
  State y_, f_, y1_, f1_, tmp_, ftmp_;
  Mode mode_ = Mode::kFree;
  bool fresh_ = false;  // an event was just applied at this state
  T t0_ = 0, s0_ = 0, a0_ = 0, slope_ = 0;
  Tally tally_;
};

}  // namespace

template <typename T>
Result integrate_dop853(const OdeSpec& spec, const Ground& g, double rtol) {
  return ReferenceRun<T>(spec, g, static_cast<T>(rtol)).run();
}
template Result integrate_dop853<long double>(const OdeSpec&, const Ground&, double);
template Result integrate_dop853<double>(const OdeSpec&, const Ground&, double);

}  // namespace vines::host::reference
