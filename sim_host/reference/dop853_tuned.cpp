// The `dop853` baseline of `vines bench`, as a competitor would write it:
// Hairer's DOP853 in double on a fixed-size state on the stack (no heap in
// the step loop), FSAL, Hairer's error norm and step control with the step
// size carried across samples (a step still ends at every sample: a_g is
// kinked there), events and the monitors (peak of |x_top|, deepest overlap)
// found on the 7th-order dense output (contd8) of the steps that need it.
// The state at an event is the step re-taken once to it, held to the
// tolerance, and the integration restarts there. Same model, modes, event
// functions and tally as the reference driver (reference.cpp), which
// locates each event by re-taking the step at every iteration.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sim_host/reference/dop853.hpp"
#include "sim_host/reference/dop853_parts.hpp"
#include "sim_host/reference/integrators.hpp"
#include "sim_host/reference/ode.hpp"
#include "sim_host/reference/tuned_ode.hpp"

namespace vines::host::reference {
namespace {

using namespace tuned;

// The largest state: the tallest frame with a device.
constexpr int kMaxSize = 2 * (kMaxStories + 1) + 1;

// The run on a frame of F floors with D device slots (F = 0: any, the
// state's size from the spec, up to kMaxSize).
template <int F, int D>
class TunedRun {
 public:
  static constexpr int N = TunedOde<F, D>::kSize;
  // Vectors padded to whole AVX2 packs (the padding stays 0).
  static constexpr int kCap = N > 0 ? (N + 3) / 4 * 4 : kMaxSize;
  using Vec = std::array<double, kCap>;

  TunedRun(const OdeSpec& spec, const Ground& g, double rtol)
      : rhs_(spec), ode_(rhs_.scene()), g_(g), n_(ode_.size()), rtol_(rtol) {
    const std::vector<double> sc = ode_.scales();
    atol_.fill(1.0);
    for (int q = 0; q < size(); ++q) atol_[q] = rtol * sc[static_cast<std::size_t>(q)];
    x_top_ = linear([this](const double* y) { return ode_.top_x(y); });
    v_top_ = linear([this](const double* y) { return ode_.top_v(y); });
    if (!ode_.has_particle()) return;
    const Affine rel = linear([this](const double* y) { return ode_.rel_pos(y); });
    const Affine rel_v = linear([this](const double* y) { return ode_.rel_vel(y); });
    const Affine hold = linear([this](const double* y) { return ode_.holding_force(y); });
    const Vec zero{};
    for (int i = 0; i < 2; ++i) {
      const double s = i == 0 ? -1.0 : 1.0;
      overlap_[i] = shifted(rel, s, ode_.overlap(zero.data(), i == 0 ? -1 : 1));
      rate_[i] = shifted(rel_v, s, 0.0);
      free_[i] = shifted(overlap_[i], 1.0, -ode_.start_depth());
      contact_[i] = shifted(overlap_[i], -1.0, 0.0);
      ride_[i] = shifted(hold, s, 0.0);
    }
  }

  Result run() {
    ode_.initial_state(y_.data());
    tally_.peak(0.0, 0.0);
    hprop_ = std::min(1e-3, 1.0 / g_.rate_hz);
    const std::vector<double>& a = *g_.samples;
    for (int k = 0; k < g_.intervals; ++k) {
      t0_ = k / g_.rate_hz;
      const double len = k + 1 == g_.intervals ? g_.t_end - t0_ : 1.0 / g_.rate_hz;
      a0_ = a[static_cast<std::size_t>(k)];
      slope_ = (a[static_cast<std::size_t>(k) + 1] - a0_) * g_.rate_hz;
      s0_ = 0.0;
      // FSAL across samples: a_g is continuous, f at the sample is the last step's.
      if (k == 0) eval(0.0, y_, k_[0]);
      while (s0_ < len) advance(len);
    }
    tally_.r.elastic_energy = y_[static_cast<std::size_t>(ode_.energy_index())];
    return tally_.r;
  }

 private:
  // An affine function of the state (an event function, a monitor):
  // c + sum_k w_k y[index_k] over its n non-zero weights.
  struct Affine {
    int n = 0;
    std::array<int, kCap> index{};
    std::array<double, kCap> w{};
    double c = 0;
  };
  int size() const { return N > 0 ? N : n_; }
  int lanes() const { return N > 0 ? kCap : n_; }  // what the vector loops run over
  static double dot(const Affine& g, const Vec& y) {
    double s = 0.0;
    for (int k = 0; k < g.n; ++k) s += g.w[k] * y[g.index[k]];
    return s;
  }
  static double at(const Affine& g, const Vec& y) { return dot(g, y) + g.c; }
  // Its time derivative along f, times h.
  static double rate(const Affine& g, const Vec& f, double h) { return h * dot(g, f); }
  // The weights of a linear function of the state, probed at the unit vectors.
  template <class L>
  Affine linear(L f) const {
    Affine g;
    Vec e{};
    for (int q = 0; q < size(); ++q) {
      e[q] = 1.0;
      if (const double w = f(e.data()); w != 0.0) g.index[g.n] = q, g.w[g.n++] = w;
      e[q] = 0.0;
    }
    return g;
  }
  static Affine shifted(Affine g, double scale, double c) {
    for (double& w : g.w) w *= scale;
    g.c = scale * g.c + c;
    return g;
  }

  void eval(double s, const Vec& y, Vec& dy) {
    ++tally_.r.rhs_evals;
    rhs_.rhs(a0_ + slope_ * s, y.data(), dy.data(), mode_);
  }
  double time(double s) const { return t0_ + s; }

  // ---- the step ----
  // out = y + h sum_J a[I][J] k_J over row I's non-zero coefficients.
  template <int I, int... J>
  void combine(double h, Vec& out) const {
    static_assert(sizeof...(J) == nonzeros(I) && ((kA<I, J> != 0.0) && ...), "the row's non-zero coefficients");
    for (int q = 0; q < lanes(); ++q) out[q] = y_[q] + h * (... + (kA<I, J> * k_[J][q]));
  }
  template <int I, int... J>
  void stage(double h) {
    combine<I, J...>(h, ys_);
    eval(s0_ + node(I) * h, ys_, k_[I]);
  }
  // Hairer's error norm of the step: the 5th- and 3rd-order estimates combined.
  template <int... J>
  double error(double h, std::integer_sequence<int, J...>) const {
    double e5 = 0.0, e3 = 0.0;
    for (int q = 0; q < lanes(); ++q) {
      const double d5 = (... + (kE5<J> * k_[J][q])), d3 = (... + (kE3<J> * k_[J][q]));
      const double w = 1.0 / (atol_[q] + rtol_ * std::max(std::fabs(y_[q]), std::fabs(y1_[q])));
      e5 += (d5 * w) * (d5 * w);
      e3 += (d3 * w) * (d3 * w);
    }
    if (e5 == 0.0 && e3 == 0.0) return 0.0;
    return std::fabs(h) * e5 / std::sqrt((e5 + 0.01 * e3) * size());
  }
  // From (s0_, y_, k_[0] = f): y1_, k_[12] = f(y1_) and the error norm.
  double step(double h) {
    stage<1, 0>(h);
    stage<2, 0, 1>(h);
    stage<3, 0, 2>(h);
    stage<4, 0, 2, 3>(h);
    stage<5, 0, 3, 4>(h);
    stage<6, 0, 3, 4, 5>(h);
    stage<7, 0, 3, 4, 5, 6>(h);
    stage<8, 0, 3, 4, 5, 6, 7>(h);
    stage<9, 0, 3, 4, 5, 6, 7, 8>(h);
    stage<10, 0, 3, 4, 5, 6, 7, 8, 9>(h);
    stage<11, 0, 3, 4, 5, 6, 7, 8, 9, 10>(h);
    combine<12, 0, 5, 6, 7, 8, 9, 10, 11>(h, y1_);
    eval(s0_ + h, y1_, k_[12]);
    return error(h, std::integer_sequence<int, 0, 5, 6, 7, 8, 9, 10, 11>{});
  }

  // ---- the dense output of the accepted step, computed once if asked ----
  template <int R, int... J>
  double dense_term(int q) const {
    return h_ * (... + (kD<R, J> * k_[J][q]));
  }
  void dense() {
    if (dense_) return;
    dense_ = true;
    stage<13, 0, 6, 7, 8, 9, 10, 11, 12>(h_);
    stage<14, 0, 5, 6, 7, 10, 11, 12, 13>(h_);
    stage<15, 0, 5, 6, 7, 8, 12, 13, 14>(h_);
    for (int q = 0; q < lanes(); ++q) {
      const double dy = y1_[q] - y_[q];
      r_[0][q] = y_[q];
      r_[1][q] = dy;
      r_[2][q] = h_ * k_[0][q] - dy;
      r_[3][q] = 2.0 * dy - h_ * (k_[0][q] + k_[12][q]);
      r_[4][q] = dense_term<0, 0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15>(q);
      r_[5][q] = dense_term<1, 0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15>(q);
      r_[6][q] = dense_term<2, 0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15>(q);
      r_[7][q] = dense_term<3, 0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15>(q);
    }
  }
  Poly along(const Affine& g) {
    dense();
    Poly p;
    for (int i = 0; i < 8; ++i) p.c[i] = dot(g, r_[i]);
    p.c[0] += g.c;
    return p;
  }
  // Root tolerance in theta: a few ulps of the time.
  double tol() const { return 16.0 * std::numeric_limits<double>::epsilon() * (t0_ + s0_ + h_) / h_; }

  // ---- mode events: g crosses zero upwards ----
  int candidates(int out[2]) const { return ode_.has_particle() ? event_walls(mode_, out) : 0; }
  // Free: overlap beyond the start depth; contact: overlap back to 0;
  // riding: the wall would have to pull.
  const Affine& event_g(int side) const {
    const int i = side < 0 ? 0 : 1;
    return mode_ == Mode::kFree ? free_[i] : in_contact(mode_) ? contact_[i] : ride_[i];
  }
  // The earliest event in the accepted step: its side (0: none) and theta
  // just past it (g > 0 there).
  int find_event(double* th_event) {
    int c[2], best = 0;
    const int nc = candidates(c);
    for (int i = 0; i < nc; ++i) {
      const Affine& g = event_g(c[i]);
      const double g0 = at(g, y_), g1 = at(g, y1_);
      if (g0 > 0.0) continue;
      double hi = -1.0;
      if (g1 > 0.0) {
        hi = locate(along(g), 0.0, 1.0, 1.0, tol()).hi;
      } else if (!riding(mode_)) {
        // A graze: the Hermite interpolant of g rises above zero inside the step.
        const double d0 = rate(g, k_[0], h_), d1 = rate(g, k_[12], h_), level = -1e-3 * ode_.start_depth();
        if (std::max(g0, g1) + hermite_bulge(g0, d0, g1, d1, 1.0) <= level) continue;
        double th[2];
        const int n = hermite_stationary(g0, d0, g1, d1, 1.0, th);
        for (int j = 0; j < n; ++j) {
          if (!(hermite_value(g0, d0, g1, d1, 1.0, th[j]) > level)) continue;
          const Poly p = along(g);
          if (!(p.at(th[j]) > 0.0)) continue;
          hi = locate(p, 0.0, th[j], 1.0, tol()).hi;
          break;
        }
      }
      if (hi < 0.0) continue;
      ++tally_.r.events;
      if (!best || hi < *th_event) *th_event = hi, best = c[i];
    }
    return best;
  }

  // ---- monitors on [0, te] of the accepted step: peak of |x_top|, deepest overlap ----
  // Every zero of g there (a sign change, or two hidden where the Hermite
  // interpolant turns back across 0 and the dense output confirms it).
  template <class On>
  void zeros(const Affine& g, double te, On on_root) {
    const double g0 = at(g, y_), d0 = rate(g, k_[0], h_);
    double g1, d1;
    if (te == 1.0) {
      g1 = at(g, y1_), d1 = rate(g, k_[12], h_);
    } else {
      const Poly p = along(g);
      g1 = p.at(te), d1 = p.slope(te);
    }
    if ((g0 < 0.0) != (g1 < 0.0)) {
      on_root(locate(along(g), 0.0, te, g1 > g0 ? 1.0 : -1.0, tol()));
      return;
    }
    const double bulge = hermite_bulge(g0, d0, g1, d1, te);
    if (g0 < 0.0 ? std::max(g0, g1) + bulge < 0.0 : std::min(g0, g1) - bulge >= 0.0) return;
    double th[2];
    const int n = hermite_stationary(g0, d0, g1, d1, te, th);
    for (int i = 0; i < n; ++i) {
      if ((hermite_value(g0, d0, g1, d1, te, th[i]) < 0.0) == (g0 < 0.0)) continue;
      const Poly p = along(g);
      const double m = th[i] * te, gm = p.at(m);
      if ((gm < 0.0) == (g0 < 0.0)) continue;
      on_root(locate(p, 0.0, m, gm > g0 ? 1.0 : -1.0, tol()));
      on_root(locate(p, m, te, g1 > gm ? 1.0 : -1.0, tol()));
      return;
    }
  }
  void monitor(double te, const Vec& ye) {
    tally_.peak(std::fabs(ode_.top_x(ye.data())), time(s0_ + te * h_));
    zeros(v_top_, te, [this](Root b) {
      ++tally_.r.events;
      const Poly x = along(x_top_);
      const double xl = std::fabs(x.at(b.lo)), xh = std::fabs(x.at(b.hi));
      tally_.peak(std::max(xl, xh), time(s0_ + (xl > xh ? b.lo : b.hi) * h_));
    });
    if (!in_contact(mode_)) return;
    const int i = mode_ == Mode::kContactLeft ? 0 : 1;
    tally_.overlap(at(overlap_[i], ye));
    zeros(rate_[i], te, [this, i](Root b) {
      ++tally_.r.events;
      const Poly d = along(overlap_[i]);
      tally_.overlap(std::max(d.at(b.lo), d.at(b.hi)));
    });
  }

  // ---- what an event does: the firmware's contact-mode transition ----
  void apply(int side) { take_event(mode_, side, ode_, y_.data(), tally_, time(s0_)); }
  // An event due before any time passes (the state already beyond a
  // surface, and approaching it in free flight): 0 if none, else the side.
  int due() const {
    int c[2];
    const int n = candidates(c);
    for (int i = 0; i < n; ++i)
      if (at(event_g(c[i]), y_) > 0.0 && (mode_ != Mode::kFree || ode_.overlap_rate(y_.data(), c[i]) > 0.0))
        return c[i];
    return 0;
  }

  // One attempted step inside the interval of length len.
  void advance(double len) {
    if (!fresh_) {
      if (const int side = due()) {
        ++tally_.r.events;
        apply(side);
        eval(s0_, y_, k_[0]);
        fresh_ = true;
        return;
      }
    }
    const bool to_end = hprop_ >= len - s0_;
    const double h = to_end ? len - s0_ : hprop_;
    if (!(h > 1e-6 * std::numeric_limits<double>::epsilon() * len))
      throw std::runtime_error("dop853: step size underflow at t = " + std::to_string(time(s0_)) + " s");
    const double err = step(h);
    // 0.9 err^(-1/8), within [0.2, 10].
    double factor = err == 0.0 ? 10.0 : std::min(10.0, std::max(0.2, 0.9 / std::sqrt(std::sqrt(std::sqrt(err)))));
    if (!(err <= 1.0)) {
      ++tally_.r.rejected;
      hprop_ = h * std::min(1.0, factor);
      rejected_ = true;
      return;
    }
    if (rejected_) factor = std::min(1.0, factor);  // no growth right after a rejection
    rejected_ = false;
    h_ = h;
    dense_ = false;

    double te = 1.0;
    const int side = find_event(&te);
    if (side) {
      // The state at the event: the step re-taken to it (8th order), held
      // to the tolerance too (a contact ends where the law's force has a
      // square-root edge, which the step and its dense output ran across).
      if (te < 1.0) {
        const double e = step(te * h);
        if (!(e <= 1.0)) {
          ++tally_.r.rejected;
          hprop_ = te * h * std::min(0.5, 0.9 / std::sqrt(std::sqrt(std::sqrt(e))));
          rejected_ = true;
          return;
        }
      }
      ++tally_.r.steps;
      monitor(te, y1_);
      s0_ = te == 1.0 && to_end ? len : s0_ + te * h;
      y_ = y1_;
      apply(side);
      eval(s0_, y_, k_[0]);
      fresh_ = true;
      return;
    }
    ++tally_.r.steps;
    monitor(1.0, y1_);
    s0_ = to_end ? len : s0_ + h;
    y_ = y1_;
    k_[0] = k_[12];
    fresh_ = false;
    hprop_ = to_end ? std::max(h * factor, hprop_) : h * factor;
  }

  TunedOde<F, D> rhs_;
  const SceneOde<double>& ode_;
  Ground g_;
  int n_;
  double rtol_;
  Vec atol_{}, y_{}, y1_{}, ys_{};
  Vec k_[Dop853Dense::kStages] = {};
  Vec r_[8] = {};
  Affine x_top_, v_top_, overlap_[2], rate_[2], free_[2], contact_[2], ride_[2];
  Mode mode_ = Mode::kFree;
  bool fresh_ = false;     // an event was just applied at this state
  bool rejected_ = false;  // the last attempt was rejected
  bool dense_ = false;     // r_ holds the accepted step's dense output
  double t0_ = 0, s0_ = 0, a0_ = 0, slope_ = 0, h_ = 0, hprop_ = 0;
  Tally tally_;
};

template <int F, int D>
Result run_tuned(const OdeSpec& spec, const Ground& g, double rtol) {
  return TunedRun<F, D>(spec, g, rtol).run();
}

}  // namespace

Result integrate_dop853_tuned(const OdeSpec& spec, const Ground& g, double rtol) {
  // The 10-story frame, bare or with a device, at its size; others at any size.
  if (spec.frame.n != 10) return run_tuned<0, 0>(spec, g, rtol);
  return spec.kind == DeviceKind::kNone ? run_tuned<10, 0>(spec, g, rtol) : run_tuned<10, 1>(spec, g, rtol);
}

}  // namespace vines::host::reference
