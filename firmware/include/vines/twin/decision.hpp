// The twin's damage decision (docs/twin.md section 5), on the node: whether,
// where, how much and since when the building lost stiffness, decided by
// tests over hypotheses (twin/hypotheses.hpp) rather than a threshold on
// each story's estimate alone.
//
// Two kinds of test, each on the stories' losses and the full covariance of
// their error:
// - absolute: the losses less the baseline's (the factors a commissioning
//   run on the healthy building identified; none: nominal), with the error
//   the estimate's own (its information, times an inflation factor, 1 by
//   calibration) plus the model's (the baseline's
//   covariance, or the healthy stories' and masses' spread about the
//   drawing);
// - change: the losses now less the losses some seconds ago (a ring of
//   snapshots, one a second), so that the model's error, the same before and
//   after, cancels (a damage that strikes during the record); the error the
//   two estimates' plus a small drift.
// A test names a story when its statistic beats the threshold and the next
// story's by the separation ("damage, story not identified" otherwise), two
// stories when the pair beats the best one by the two-story margin. A
// candidate held for the hold time raises the alarm, which latches. The onset
// is where the estimator's change score last rose, or else where the named
// story's change began in the snapshots.
#pragma once

#include <cmath>

#include "vines/twin/hypotheses.hpp"

namespace vines::twin {

// The decision's settings (the twin image's, see twin/image.hpp).
template <typename S>
struct DecisionSettings {
  S threshold = S(0);         // one-story statistic for an absolute candidate
  S threshold_change = S(0);  // ...for a change candidate
  S two = S(0);               // two stories: the pair's statistic beyond the best story's by this
  S separation = S(0);        // a story named: its statistic beyond the next story's by this
  S inflation = S(1);         // the estimate's covariance times this
  S drift_var = S(0);         // a change test's model drift, variance per story
  long snap_steps = 1;        // steps between snapshots
  long hold_steps = 0;        // a candidate held this long raises the alarm
  long restart_steps = 0;     // the estimator restarts at most once in this many steps
};

template <typename S, int N>
class Decision {
 public:
  static constexpr int kRing = 64;                 // snapshots kept (seconds at one a second)
  static constexpr int kLags = 5;                  // change tests, against snapshots this far back:
  static constexpr int kLag[kLags] = {4, 8, 16, 32, 63};

  // base: the baseline's losses (n); sigma0: the model's covariance (n x n).
  void init(int n, const DecisionSettings<S>& s, const S* base, const S (*sigma0)[N]) {
    n_ = n, set_ = s, base_ = base, sigma0_ = sigma0;
    count_ = 0, head_ = 0, lag_turn_ = 0, held_ = 0, since_restart_ = s.restart_steps;
    restart_ = false, suspected_ = false, now_ = 0, rise_ = -1;
    detected_ = false, story_ = -1, second_ = -1, onset_ = -1;
    size_ = size2_ = S(0);
    for (auto& l : lag_) l.valid = false;
    abs_.valid = false;
    for (int j = 0; j < N; ++j) evidence_[j] = S(0);
  }

  // Every step k: a snapshot of the losses every snap_steps.
  void observe(long k, const S* loss, S sdmax) {
    if (k % set_.snap_steps != 0) return;
    Snap& s = ring_[head_];
    for (int j = 0; j < n_; ++j) s.loss[j] = loss[j];
    s.sdmax = sdmax, s.k = k;
    head_ = (head_ + 1) % kRing;
    if (count_ < kRing) ++count_;
  }

  // The absolute test on the losses with the estimate's covariance sig.
  void absolute(const S* loss, const S (&sig)[N][N]) {
    S A[N][N], th[N] = {};
    for (int a = 0; a < n_; ++a) {
      th[a] = loss[a] - base_[a];
      for (int b = 0; b <= a; ++b) A[a][b] = set_.inflation * sig[a][b] + sigma0_[a][b];
    }
    run(A, th, -1, &abs_);
  }

  // The next change test in turn: the losses now against the snapshot its
  // lag back, if there is one.
  void change(const S* loss, const S (&sig)[N][N], S sdmax) {
    const int i = lag_turn_;
    lag_turn_ = (lag_turn_ + 1) % kLags;
    Test& t = lag_[i];
    t.valid = false;
    if (kLag[i] >= count_) return;
    const int r = (head_ - 1 - kLag[i] + 2 * kRing) % kRing;
    const Snap& ref = ring_[r];
    const S rho = sdmax > S(0) ? (ref.sdmax / sdmax) * (ref.sdmax / sdmax) : S(1);
    S A[N][N], th[N] = {};
    for (int a = 0; a < n_; ++a) {
      th[a] = loss[a] - ref.loss[a];
      for (int b = 0; b <= a; ++b) A[a][b] = set_.inflation * (S(1) + rho) * sig[a][b] + (a == b ? set_.drift_var : S(0));
    }
    run(A, th, r, &t);
  }

  // After the tests: the strongest candidate, held, latched; its story (or
  // none identified), size, second story and onset. elapsed: steps since the
  // last decide().
  void decide(long elapsed, bool suspected = false) {
    const Test* best = nullptr;
    S best_margin(0);
    auto consider = [&](const Test& t, S thr) {
      if (!t.valid || t.h.story < 0) return;
      const S margin = t.h.one - thr;
      if (margin > S(0) && (best == nullptr || margin > best_margin)) best = &t, best_margin = margin;
    };
    consider(abs_, set_.threshold);
    for (const Test& t : lag_) consider(t, set_.threshold_change);
    const Test& shown = best ? *best : abs_;
    for (int j = 0; j < n_; ++j) evidence_[j] = shown.valid ? shown.h.stat[j] : S(0);
    held_ = best ? held_ + elapsed : 0;
    // A change suspected (the estimator's score): it restarts its
    // information, so that it follows the changed building rather than a
    // compromise between the building before and after (section 5).
    since_restart_ += elapsed;
    now_ += elapsed;
    if (suspected && !suspected_) rise_ = now_;  // where the score rose: the change's onset
    suspected_ = suspected;
    if (suspected && since_restart_ >= set_.restart_steps && !detected_) restart_ = true, since_restart_ = 0;
    if (!best || held_ < set_.hold_steps) return;
    detected_ = true;
    const Hypotheses<S, N>& h = best->h;
    if (h.two - h.one > set_.two) {
      story_ = h.a, second_ = h.b, size_ = h.size_a, size2_ = h.size_b;
    } else {
      story_ = h.one - h.runner > set_.separation ? h.story : -1;
      second_ = -1, size_ = h.size[h.story], size2_ = S(0);
    }
    // The onset: where the score last rose, if it did within the snapshots'
    // span; else where the named story's change began in them.
    const bool risen = rise_ >= 0 && now_ - rise_ <= static_cast<long>(kRing) * set_.snap_steps;
    onset_ = risen ? rise_ : onset(*best, h.story);
  }

  // Whether the estimator should restart its information now (once per
  // suspicion: the call clears it).
  bool take_restart() {
    const bool r = restart_;
    restart_ = false;
    return r;
  }

  // ---- outputs -------------------------------------------------------------
  bool detected() const { return detected_; }
  int story() const { return detected_ ? story_ + 1 : 0; }    // 1-based; 0: none named
  int second_story() const { return detected_ ? second_ + 1 : 0; }
  S size() const { return size_; }
  S second_size() const { return size2_; }
  long onset_step() const { return onset_; }                 // -1: none
  S evidence(int j) const { return evidence_[j]; }           // story j's statistic in the leading test
  S threshold() const { return set_.threshold; }

 private:
  struct Snap {
    S loss[N] = {};
    S sdmax = S(0);
    long k = 0;
  };
  struct Test {
    bool valid = false;
    int ref = -1;    // the snapshot it is against (-1: the baseline)
    S row[N] = {};   // its best story's row of the precision
    Hypotheses<S, N> h;
  };

  void run(S (&A)[N][N], const S* th, int ref, Test* t) {
    t->valid = false;
    if (!cholesky(A, n_)) return;
    S P[N][N];
    inverse_from_factor(A, n_, P);
    test_hypotheses(P, th, n_, &t->h);
    t->ref = ref;
    if (t->h.story >= 0)
      for (int b = 0; b < n_; ++b) t->row[b] = P[t->h.story][b];
    t->valid = true;
  }

  // Story j's size in snapshot s, as the test sees it (its precision's row).
  S projected(const Test& t, int j, const Snap& s) const {
    const Snap* ref = t.ref >= 0 ? &ring_[t.ref] : nullptr;
    S u(0);
    for (int b = 0; b < n_; ++b) u += t.row[b] * (s.loss[b] - (ref ? ref->loss[b] : base_[b]));
    return u / t.row[j];
  }

  // The onset: between the last snapshot (from the test's reference on)
  // where story j's size was under a quarter of its size now, and the next.
  long onset(const Test& t, int j) const {
    if (j < 0 || count_ == 0) return -1;
    const int newest = (head_ - 1 + kRing) % kRing;
    const S now = projected(t, j, ring_[newest]);
    const int span = t.ref >= 0 ? (newest - t.ref + kRing) % kRing : count_ - 1;
    for (int back = 1; back <= span; ++back) {
      const int i = (newest - back + kRing) % kRing;
      if (projected(t, j, ring_[i]) <= S(0.25) * now) return (ring_[i].k + ring_[(i + 1) % kRing].k) / 2;
    }
    return ring_[(newest - span + kRing) % kRing].k;
  }

  int n_ = 0;
  DecisionSettings<S> set_;
  const S* base_ = nullptr;
  const S (*sigma0_)[N] = nullptr;
  Snap ring_[kRing];
  int count_ = 0, head_ = 0, lag_turn_ = 0;
  Test abs_, lag_[kLags];
  long held_ = 0, onset_ = -1, since_restart_ = 0, now_ = 0, rise_ = -1;
  bool detected_ = false, restart_ = false, suspected_ = false;
  int story_ = -1, second_ = -1;
  S size_ = S(0), size2_ = S(0);
  S evidence_[N] = {};
};

}  // namespace vines::twin
