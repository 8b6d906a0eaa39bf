// The twin's damage decision (docs/twin.md section 5), on the node: whether,
// where, how much and since when the building lost stiffness, decided by
// tests over hypotheses (twin/hypotheses.hpp) rather than a threshold on
// each story's estimate alone.
//
// Two kinds of test, each on the stories' losses and the full covariance of
// their error:
// - absolute: the losses less the baseline's (the factors a commissioning
//   run on the healthy building identified; none: nominal), with the error
//   the estimate's own (its information, times an inflation factor) plus the
//   model's (the baseline's covariance, or the healthy stories' and masses'
//   spread about the drawing);
// - change at an onset (a damage that strikes during the record): the
//   building identified from the data before a candidate onset against the
//   building identified from the data after it, each a least-squares fit of
//   its own window (the estimator's linearised information and right-hand
//   side, summed since the start and snapshotted once a second), so that the
//   model's error, the same before and after, cancels; the error the two
//   windows' plus a small drift. Every snapshot of the ring is a candidate
//   onset, scanned in turn (Willsky and Jones' generalised likelihood ratio
//   for a jump at an unknown time); the best candidate dates the onset.
// A test names a story when its statistic beats the threshold and the next
// story's by the separation ("damage, story not identified" otherwise), two
// stories when the pair beats the best one by the two-story margin. A
// candidate held for the hold time raises the alarm, which latches; the
// verdict is the last candidate held, but once a change test's is reported
// only a stronger change test's replaces it. Sizes are shares of the
// stiffness the story had (before the onset, or in the baseline).
#pragma once

#include <cmath>

#include "vines/twin/hypotheses.hpp"

namespace vines::twin {

// The decision's settings (the twin image's, see twin/image.hpp).
template <typename S>
struct DecisionSettings {
  S threshold = S(0);         // one-story statistic for an absolute candidate
  S threshold_change = S(0);  // ...for a change candidate
  S two = S(0);               // two stories: the pair's statistic beyond the best story's by this...
  S two_share = S(0);         // ...and by this share of it (a large loss's misfit grows with it)
  S separation = S(0);        // a story named: its statistic beyond the next story's by this
  S inflation = S(1);         // the estimate's covariance times this
  S drift_var = S(0);         // a change test's model drift, variance per story
  long snap_steps = 1;        // steps between snapshots
  long hold_steps = 0;        // a candidate held this long raises the alarm
  long restart_steps = 0;     // the estimator restarts at most once in this many steps
  S before_var_max = S(1);    // a candidate onset: every story's fit before it within this variance
  S fit_gate = S(1e30);       // the absolute test: the best hypothesis leaves at most this (and two_share of it) unexplained
};

// A symmetric matrix of the parameters (the stories and the device's), its
// lower triangle packed row by row.
inline constexpr int tri(int a, int b) { return a * (a + 1) / 2 + b; }  // a >= b

template <typename S, int N>
class Decision {
 public:
  static constexpr int kP = N + 1;                // parameters at most: the stories and the device's
  static constexpr int kTri = kP * (kP + 1) / 2;  // a packed kP x kP
  static constexpr int kRing = 24;                // snapshots kept, one a second (the M7 double image in 64 KB)
  static constexpr int kMinAfter = 2;             // a change's window after its onset: at least this many snapshots

  // n stories of np parameters; base: the baseline's losses (n); sigma0: the
  // model's covariance (n x n); prior: each parameter's prior information.
  void init(int n, int np, const DecisionSettings<S>& s, const S* base, const S (*sigma0)[N], const S* prior) {
    n_ = n, np_ = np, set_ = s, base_ = base, sigma0_ = sigma0, prior_ = prior;
    count_ = 0, head_ = 0, held_ = 0, since_restart_ = s.restart_steps;
    restart_ = false, suspected_ = false, now_ = 0, rise_ = -1;
    detected_ = false, story_ = -1, second_ = -1, onset_ = -1;
    size_ = size2_ = S(0);
    abs_.valid = scan_.valid = last_.valid = false;
    back_ = kMinAfter, phase_ = 0;
    for (int j = 0; j < N; ++j) evidence_[j] = S(0);
    lead_thr_ = s.threshold, reported_margin_ = S(0), reported_change_ = false;
  }

  // Every step k: a snapshot every snap_steps of the losses and of the
  // change information so far (J packed, b: twin/estimator.hpp).
  void observe(long k, const S* loss, const S* J, const S* b) {
    if (k % set_.snap_steps != 0) return;
    Snap& s = ring_[head_];
    for (int j = 0; j < n_; ++j) s.loss[j] = loss[j];
    for (int i = 0; i < tri(np_ - 1, np_ - 1) + 1; ++i) s.J[i] = J[i];
    for (int a = 0; a < np_; ++a) s.b[a] = b[a];
    s.k = k;
    head_ = (head_ + 1) % kRing;
    if (count_ < kRing) ++count_;
  }

  // The absolute test on the losses with the estimate's covariance sig,
  // times misfit (>= 1: the model's misfit, twin/estimator.hpp).
  void absolute(const S* loss, const S (&sig)[N][N], S misfit) {
    S A[N][N], th[N] = {};
    for (int a = 0; a < n_; ++a) {
      th[a] = loss[a] - base_[a];
      for (int b = 0; b <= a; ++b) A[a][b] = set_.inflation * misfit * sig[a][b] + sigma0_[a][b];
    }
    run(A, th, &abs_);
    abs_.onset_k = -1;
    // The hypotheses must explain the estimate: what the best of them leaves
    // (chi-square with n - 1 degrees of freedom while one holds) beyond the
    // gate says none does (a record the model does not explain, whose
    // estimates err in a pattern no loss makes): no candidate.
    const Hypotheses<S, N>& h = abs_.h;
    const S best = h.two > h.one ? h.two : h.one;
    if (abs_.valid && h.total - best > set_.fit_gate + set_.two_share * best) abs_.valid = false;
  }

  // One part of the change scan, on the information so far (J, b): a
  // candidate onset's window before it, its window after it, their test.
  // Candidates go from the newest snapshot kMinAfter back to the oldest;
  // the best of a whole scan is kept until the next scan ends.
  void scan(const S* J, const S* b) {
    if (count_ <= kMinAfter) return;
    if (phase_ == 0) {
      if (back_ >= count_) {  // the scan is over
        last_ = scan_, scan_.valid = false, back_ = kMinAfter;
        return;
      }
      ref_ = (head_ - 1 - back_ + 2 * kRing) % kRing;
      ref_k_ = ring_[ref_].k;
      // A window before that is no reference yet (the prior, a record's
      // first seconds) ends the scan: the older ones know less still.
      phase_ = fit(ring_[ref_].J, nullptr, ring_[ref_].b, nullptr, nullptr, before_, P1_) ? 1 : 0;
      for (int a = 0; a < n_ && phase_ == 1; ++a)
        if (P1_[a][a] > set_.before_var_max) phase_ = 0;
      if (phase_ == 0) back_ = count_;
      return;
    }
    const Snap& r = ring_[ref_];
    if (r.k != ref_k_) {  // overwritten by a newer snapshot meanwhile
      phase_ = 0, ++back_;
      return;
    }
    if (phase_ == 1) {
      phase_ = fit(J, r.J, b, r.b, before_, after_, P2_) ? 2 : 0;
      if (phase_ == 0) ++back_;
      return;
    }
    S A[N][N], th[N] = {};
    for (int a = 0; a < n_; ++a) {
      th[a] = after_[a] - before_[a];
      for (int c = 0; c <= a; ++c)
        A[a][c] = set_.inflation * (P1_[a][c] + P2_[a][c]) + (a == c ? set_.drift_var : S(0));
    }
    Test cand;
    run(A, th, &cand);
    cand.onset_k = r.k;
    for (int a = 0; a < n_; ++a) cand.before[a] = before_[a];
    if (cand.valid && cand.h.story >= 0 && (!scan_.valid || cand.h.one > scan_.h.one)) scan_ = cand;
    phase_ = 0, ++back_;
  }

  // After the tests: the strongest candidate, held, latched; its story (or
  // none identified), size, second story and onset. elapsed: steps since the
  // last decide().
  void decide(long elapsed, bool suspected = false) {
    // The leading test: the one whose best story comes nearest its
    // threshold (or beats it by most); a candidate if it beats it.
    const Test* lead = nullptr;
    S lead_margin(0);
    auto consider = [&](const Test& t, S thr) {
      if (!t.valid || t.h.story < 0) return;
      const S margin = t.h.one - thr;
      if (lead == nullptr || margin > lead_margin) lead = &t, lead_margin = margin, lead_thr_ = thr;
    };
    consider(abs_, set_.threshold);
    consider(last_, set_.threshold_change);
    consider(scan_, set_.threshold_change);
    for (int j = 0; j < n_; ++j) evidence_[j] = lead ? lead->h.stat[j] : S(0);
    const Test* best = lead && lead_margin > S(0) ? lead : nullptr;
    held_ = best ? held_ + elapsed : 0;
    // A change suspected (the estimator's score): it restarts its
    // information, so that it follows the changed building rather than a
    // compromise between the building before and after (section 5).
    since_restart_ += elapsed;
    now_ += elapsed;
    if (suspected && !suspected_) rise_ = now_;  // where the score rose
    suspected_ = suspected;
    if (suspected && since_restart_ >= set_.restart_steps && !detected_) restart_ = true, since_restart_ = 0;
    // The verdict: the last candidate held, but for a change test's weaker
    // than the change test's it stands for (its evidence grows with the data
    // after its onset, until the onset leaves the snapshots' span and only
    // later, weaker candidates remain), and against the absolute test's: the
    // change test measures the change alone, the absolute test the change
    // plus the building's own departure from its drawing or baseline (its
    // size off by that departure, its onset only where the score rose).
    if (!best || held_ < set_.hold_steps) return;
    if (detected_ && reported_change_ && (best->onset_k < 0 || lead_margin < reported_margin_)) return;
    detected_ = true, reported_margin_ = lead_margin, reported_change_ = best->onset_k >= 0;
    const Hypotheses<S, N>& h = best->h;
    // Sizes as shares of the stiffness the story had: of the window before
    // the onset's fit, or of the baseline's (the drawing's without one).
    const S* ref = best->onset_k >= 0 ? best->before : base_;
    if (h.two - h.one > set_.two + set_.two_share * h.one) {
      story_ = h.a, second_ = h.b, size_ = share(h.size_a, ref[h.a]), size2_ = share(h.size_b, ref[h.b]);
    } else {
      story_ = h.one - h.runner > set_.separation ? h.story : -1;
      second_ = -1, size_ = share(h.size[h.story], ref[h.story]), size2_ = S(0);
    }
    // The onset: a change test's candidate; for the absolute test, where the
    // score last rose, if it did within the snapshots' span, else where the
    // named story's loss began in them.
    const bool risen = rise_ >= 0 && now_ - rise_ <= static_cast<long>(kRing) * set_.snap_steps;
    onset_ = best->onset_k >= 0 ? best->onset_k : risen ? rise_ : onset(h.story);
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
  S threshold() const { return lead_thr_; }                  // the leading test's threshold

 private:
  struct Snap {
    S loss[N] = {};
    S J[kTri] = {}, b[kP] = {};
    long k = -1;
  };
  struct Test {
    bool valid = false;
    long onset_k = -1;  // a change test's onset candidate (-1: the absolute test)
    S before[N] = {};   // a change test's: the losses of its window before the onset
    S row[N] = {};      // its best story's row of the precision
    Hypotheses<S, N> h;
  };

  // A loss d from a story that had lost ref already, as a share of what it had.
  static S share(S d, S ref) { return ref < S(1) ? d / (S(1) - ref) : d; }

  void run(S (&A)[N][N], const S* th, Test* t) const {
    t->valid = false;
    if (!cholesky(A, n_)) return;
    S P[N][N];
    inverse_from_factor(A, n_, P);
    test_hypotheses(P, th, n_, &t->h);
    if (t->h.story >= 0)
      for (int b = 0; b < n_; ++b) t->row[b] = P[t->h.story][b];
    t->valid = true;
  }

  // One window's fit: information J less J0 (if given) plus the prior, right
  // side b less b0 plus the prior times pull (the window before: a short
  // window after an onset leans on it, not on the drawing); the parameters
  // theta and the stories' block of their covariance.
  bool fit(const S* J, const S* J0, const S* b, const S* b0, const S* pull, S (&theta)[kP], S (&P)[N][N]) const {
    S F[kP][kP];
    for (int a = 0; a < np_; ++a)
      for (int c = 0; c <= a; ++c) F[a][c] = J[tri(a, c)] - (J0 ? J0[tri(a, c)] : S(0)) + (a == c ? prior_[a] : S(0));
    if (!cholesky(F, np_)) return false;
    for (int a = 0; a < np_; ++a) theta[a] = b[a] - (b0 ? b0[a] : S(0)) + (pull ? prior_[a] * pull[a] : S(0));
    solve_from_factor(F, np_, theta);
    S Q[kP][kP];
    inverse_from_factor(F, np_, Q);
    for (int a = 0; a < n_; ++a)
      for (int c = 0; c < n_; ++c) P[a][c] = Q[a][c];
    return true;
  }

  // The absolute test's onset: between the last snapshot where story j's
  // size, as the test projects it, was under a quarter of its size now, and
  // the next.
  S projected(int j, const Snap& s) const {
    S u(0);
    for (int b = 0; b < n_; ++b) u += abs_.row[b] * (s.loss[b] - base_[b]);
    return u / abs_.row[j];
  }
  long onset(int j) const {
    if (j < 0 || count_ == 0) return -1;
    const int newest = (head_ - 1 + kRing) % kRing;
    const S now = projected(j, ring_[newest]);
    for (int back = 1; back < count_; ++back) {
      const int i = (newest - back + kRing) % kRing;
      if (projected(j, ring_[i]) <= S(0.25) * now) return (ring_[i].k + ring_[(i + 1) % kRing].k) / 2;
    }
    return ring_[(newest - count_ + 1 + kRing) % kRing].k;
  }

  int n_ = 0, np_ = 0;
  DecisionSettings<S> set_;
  const S* base_ = nullptr;
  const S (*sigma0_)[N] = nullptr;
  const S* prior_ = nullptr;
  Snap ring_[kRing];
  int count_ = 0, head_ = 0;
  // The absolute test; the change scan's best so far, the last whole scan's
  // best.
  Test abs_, scan_, last_;
  int back_ = kMinAfter, phase_ = 0, ref_ = 0;
  long ref_k_ = -1;
  S before_[kP] = {}, after_[kP] = {}, P1_[N][N] = {}, P2_[N][N] = {};
  long held_ = 0, onset_ = -1, since_restart_ = 0, now_ = 0, rise_ = -1;
  bool detected_ = false, restart_ = false, suspected_ = false, reported_change_ = false;
  int story_ = -1, second_ = -1;
  S size_ = S(0), size2_ = S(0);
  S evidence_[N] = {}, lead_thr_ = S(0), reported_margin_ = S(0);
};

}  // namespace vines::twin
