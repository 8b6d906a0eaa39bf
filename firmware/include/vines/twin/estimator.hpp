// The twin node's estimator (docs/twin.md): a Kalman filter that keeps the
// frame's state on the measured floor accelerations, with the device's force
// as an unknown input (VI NES) or the TMD as two more states, and a recursive
// prediction-error identification of each story's stiffness and of the
// device (the TMD's spring; the mass a VI NES floor carries, which a stuck
// sphere adds to), with their uncertainty and a damage decision.
//
// Everything the node needs is designed on the host and streamed in as the
// twin image (twin/image.hpp): the steady-state gain, the discrete model, the
// damage patterns. Per step the node does matrix-vector products only: no
// covariance recursion for the state (the gain is fixed), one for the losses
// in information form (a sum of outer products, positive semi-definite by
// construction) solved by Cholesky every few steps. Fixed capacity for N
// stories, no heap; S is double or float (transitions stored less identity,
// so float keeps their small part).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vines/twin/decision.hpp"
#include "vines/twin/image_decoder.hpp"

namespace vines::twin {

template <typename S, int N>
class Estimator : public ImageDecoder<S, N> {
 public:
  using Base = ImageDecoder<S, N>;
  using Base::kQ, Base::kX, Base::kP, Base::kY;

  // ---- the loop ------------------------------------------------------------
  // At rest at sample 0 (y: ny floor accelerations, or nullptr: none).
  void init(S a0, const double* y, int ny) {
    for (int i = 0; i < kX; ++i) z_[i] = S(0);
    for (int j = 0; j < kP; ++j) {
      loss_[j] = S(0), g_[j] = S(0), sd_[j] = S(0), held_[j] = 0;
      for (int i = 0; i < kX; ++i) s_[j][i] = S(0);
      for (int i = 0; i < kP; ++i) J_[j][i] = S(0);
      bc_[j] = S(0);
    }
    for (S& v : Jc_) v = S(0);
    for (int i = 0; i < kY; ++i) r2_[i] = q2_[i] = var_[i], eps_[i] = S(0);
    since_ = 0, k_ = 0, phase_ = 0, score_ = S(0), misfit_ = S(0);
    lam_update_ = static_cast<S>(std::pow(set_[kForget], static_cast<double>(update_steps_)));
    for (int a = 0; a < kP; ++a) {
      Gs_[a] = S(0);
      for (int b = 0; b < kP; ++b) J0_[a][b] = Is_[a][b] = S(0);
    }
    impact_left_ = 0, calm_ = 0;
    device_alarm_ = false;
    factored_ = false;
    a_ = a0;
    dec_.init(d_.stories, d_.np, decision_settings(), base_, sigma0_, prior_);
    update(y, ny);
    refresh_sd();
    dec_.observe(k_, loss_, Jc_, bc_);
  }

  // One sensor period to ground acceleration a1, then the measurements y.
  void step(S a1, const double* y, int ny) {
    predict(a1);
    update(y, ny);
    dec_.observe(++k_, loss_, Jc_, bc_);
    if (++since_ >= update_steps_) {
      since_ = 0;
      solve();
      device_decide();
      phase_ = 1;
    } else if (phase_ > 0) {
      decision_phase();
    } else {
      dec_.scan(Jc_, bc_);
    }
  }

  // ---- outputs -------------------------------------------------------------
  S x(int floor) const { return z_[floor]; }                // relative displacement [m], 0-based
  S force() const { return d_.extra == TwinExtra::kForce ? z_[2 * d_.nq] * S(set_[kForceScale]) : S(0); }
  S acc_top() const {                                        // absolute top-floor acceleration
    S a = dot(top_c_, z_, d_.nx);
    for (int j = 0; j < d_.np; ++j) a += top_h_[j] * loss_[j] * w(j, z_);
    return a;
  }
  S loss(int j) const { return loss_[j]; }                   // 1 - eta_j
  TwinParam kind(int j) const { return static_cast<TwinParam>(kind_[j]); }
  S loss_sd(int j) const { return sd_[j]; }
  S innovation(int i) const { return eps_[i]; }
  // The decision (twin/decision.hpp): detected; the story (1-based; 0: none
  // named), a second one, their sizes; the onset's step (-1: none); each
  // story's statistic in the leading test, and the absolute test's threshold.
  int alarm_story() const { return dec_.story(); }
  int second_story() const { return dec_.second_story(); }
  S damage_size() const { return dec_.size(); }
  S second_size() const { return dec_.second_size(); }
  long onset_step() const { return dec_.onset_step(); }
  S evidence(int j) const { return dec_.evidence(j); }
  S evidence_threshold() const { return dec_.threshold(); }
  bool detected() const { return dec_.detected(); }
  S change_score() const { return score_; }  // the score statistic (section 5)
  bool device_alarm() const { return device_alarm_; }
  // An impact (VI NES): the innovations jumped, the impact gain is on; the
  // frame's model does not explain these samples.
  bool impact() const { return impact_left_ > 0 && d_.extra == TwinExtra::kForce; }

 private:
  using Base::d_, Base::set_, Base::kind_, Base::dA_, Base::B0_, Base::B1_, Base::G_, Base::W_;
  using Base::L_, Base::Lq_, Base::C_, Base::H_, Base::top_c_, Base::top_h_, Base::prior_, Base::cap_;
  using Base::var_, Base::update_steps_, Base::hold_steps_, Base::base_, Base::sigma0_;

  // ---- filter ----------------------------------------------------------------
  static S dot(const S* a, const S* b, int n) {
    S t(0);
    for (int i = 0; i < n; ++i) t += a[i] * b[i];
    return t;
  }
  // Parameter j's signal on state z: a spring's drift (with stiffness-
  // proportional damping, plus c_d times its rate), a floor's absolute
  // acceleration.
  S w(int j, const S* z) const { return dot(W_[j], z, d_.nx); }

  // z <- z + dA z + B0 a0 + B1 a1 + sum_j G_j loss_j w_j(z); each sensitivity
  // s_j <- s_j + dA s_j + G_j w_j(z).
  void predict(S a1) {
    const int nx = d_.nx, np = d_.np;
    S wz[kP];
    for (int j = 0; j < np; ++j) wz[j] = w(j, z_);
    S zn[kX];
    for (int i = 0; i < nx; ++i) {
      S t = z_[i] + dot(dA_[i], z_, nx) + B0_[i] * a_ + B1_[i] * a1;
      for (int j = 0; j < np; ++j) t += G_[j][i] * loss_[j] * wz[j];
      zn[i] = t;
    }
    for (int i = 0; i < nx; ++i) z_[i] = zn[i];
    for (int j = 0; j < np; ++j) {
      S* s = s_[j];
      for (int i = 0; i < nx; ++i) zn[i] = s[i] + dot(dA_[i], s, nx) + G_[j][i] * wz[j];
      for (int i = 0; i < nx; ++i) s[i] = zn[i];
    }
    a_ = a1;
  }

  // The measurement update and the losses' information: innovation eps =
  // y - C z - sum_j H_j loss_j w_j(z); psi_j = C s_j + H_j w_j(z) its
  // sensitivity to loss_j; z += L eps, s_j -= L psi_j.
  void update(const double* y, int ny) {
    if (!y || ny != d_.ny) {
      for (int i = 0; i < kY; ++i) eps_[i] = S(0);
      return;
    }
    const int nx = d_.nx, np = d_.np;
    S wz[kP];
    for (int j = 0; j < np; ++j) wz[j] = w(j, z_);
    S psi[kY][kP];
    const S jump = static_cast<S>(set_[kJumpSigma]);
    bool impact = false;
    for (int i = 0; i < ny; ++i) {
      S yh = dot(C_[i], z_, nx);
      for (int j = 0; j < np; ++j) {
        yh += H_[i][j] * loss_[j] * wz[j];
        psi[i][j] = dot(C_[i], s_[j], nx) + H_[i][j] * wz[j];
      }
      eps_[i] = static_cast<S>(y[i]) - yh;
      impact = impact || eps_[i] * eps_[i] > jump * jump * (q2_[i] > var_[i] ? q2_[i] : var_[i]);
    }
    // The level a jump is measured against: the quiet samples' running mean
    // square, never below the design's; a model that is off (a sphere stuck
    // on its floor) raises it, an impact does not.
    if (!impact)
      for (int i = 0; i < ny; ++i) q2_[i] += static_cast<S>(set_[kInnovAlpha]) * (eps_[i] * eps_[i] - q2_[i]);
    // The gain: the quiet one (the device's force held near zero) unless an
    // innovation jumps beyond kJumpSigma of its quiet sd, then the impact
    // one (the force free) for kJumpHold steps.
    if (impact) impact_left_ = static_cast<long>(set_[kJumpHold]);
    calm_ = impact_left_ > 0 ? 0 : calm_ + 1;
    const bool explained = d_.extra != TwinExtra::kForce || calm_ > static_cast<long>(set_[kCalmSteps]);
    const S(*L)[kY] = impact_left_ > 0 ? L_ : Lq_;
    if (impact_left_ > 0) --impact_left_;
    for (int r = 0; r < nx; ++r) z_[r] += dot(L[r], eps_, ny);
    for (int j = 0; j < np; ++j)
      for (int r = 0; r < nx; ++r) {
        S t(0);
        for (int i = 0; i < ny; ++i) t += L[r][i] * psi[i][j];
        s_[j][r] -= t;
      }
    // Information with forgetting, each channel weighted by its running
    // innovation mean square (never below the design's innovation variance).
    const S lam = static_cast<S>(set_[kForget]), alpha = static_cast<S>(set_[kInnovAlpha]);
    for (int a = 0; a < np; ++a) {
      g_[a] *= lam;
      for (int b = 0; b <= a; ++b) J_[a][b] *= lam;
    }
    for (int i = 0; i < ny; ++i) {
      r2_[i] += alpha * (eps_[i] * eps_[i] - r2_[i]);
      const S wt = S(1) / (r2_[i] > var_[i] ? r2_[i] : var_[i]);
      for (int a = 0; a < np; ++a) {
        const S pa = wt * psi[i][a];
        g_[a] += pa * eps_[i];
        for (int b = 0; b <= a; ++b) J_[a][b] += pa * psi[i][b];
      }
      if (!explained) continue;
      // The change tests' information, summed since the start without
      // forgetting: a least-squares fit of any window of it is J^-1 b, the
      // innovation linearised about the estimate of its step (eps less
      // psi (theta - loss)), so that each window's fit is its own whatever
      // the estimate did meanwhile. A VI NES's impacts and the kCalmSteps
      // after each left out: the frame's model does not explain them.
      S yl = eps_[i];
      for (int a = 0; a < np; ++a) yl += psi[i][a] * loss_[a];
      for (int a = 0; a < np; ++a) {
        const S pa = wt * psi[i][a];
        bc_[a] += pa * yl;
        for (int b = 0; b <= a; ++b) Jc_[tri(a, b)] += pa * psi[i][b];
      }
    }
  }

  // Cholesky of J + prior (lower); false if not positive.
  bool factor(S (&F)[kP][kP]) const {
    for (int a = 0; a < d_.np; ++a)
      for (int b = 0; b <= a; ++b) F[a][b] = J_[a][b] + (a == b ? prior_[a] : S(0));
    return cholesky(F, d_.np);
  }
  // Gauss-Newton step on the losses from the gradient since the last one.
  void solve() {
    const int np = d_.np;
    // The score over the last seconds (section 5): the gradients and the
    // information gathered since the last update, with their own forgetting.
    const S ls = static_cast<S>(set_[kScoreForget]);
    for (int a = 0; a < np; ++a) {
      Gs_[a] = ls * Gs_[a] + g_[a];
      for (int b = 0; b <= a; ++b) {
        Is_[a][b] = ls * Is_[a][b] + (J_[a][b] - lam_update_ * J0_[a][b]);
        J0_[a][b] = J_[a][b];
      }
    }
    factored_ = factor(F_);
    if (!factored_) return;
    const S(&F)[kP][kP] = F_;
    S u[kP];
    for (int a = 0; a < np; ++a) u[a] = g_[a];
    solve_from_factor(F, np, u);
    // A trust region: no parameter moves by more than its cap an update (the
    // sensitivities are a linearisation; a long step on little information
    // lands where they no longer hold).
    const S lo = static_cast<S>(set_[kLossLow]), hi = static_cast<S>(set_[kLossHigh]);
    // The state moves with the parameters, to first order (the posterior
    // sensitivities): as if they had always had their new values. Without
    // it the state keeps the old values' error for the filter's memory, the
    // innovations keep asking for the same correction, and the steps
    // overshoot.
    const int nx = d_.nx;
    for (int a = 0; a < np; ++a) {
      const S cap = cap_[a];
      const S step = u[a] < -cap ? -cap : (u[a] > cap ? cap : u[a]);
      const S v = loss_[a] + step;
      const S next = v < lo ? lo : (v > hi ? hi : v);
      for (int i = 0; i < nx; ++i) z_[i] += s_[a][i] * (next - loss_[a]);
      loss_[a] = next;
      g_[a] = S(0);
    }
    sds(F);
  }
  void refresh_sd() {
    S F[kP][kP];
    if (factor(F)) sds(F);
  }
  // Standard deviations: the diagonal of (J + prior)^-1 from its factor,
  // column by column (e_a solved forward, its squared norm).
  void sds(const S (&F)[kP][kP]) {
    const int np = d_.np;
    for (int a = 0; a < np; ++a) {
      S v[kP];
      S ss(0);
      for (int r = a; r < np; ++r) {
        S t = r == a ? S(1) : S(0);
        for (int c = a; c < r; ++c) t -= F[r][c] * v[c];
        v[r] = t / F[r][r];
        ss += v[r] * v[r];
      }
      sd_[a] = std::sqrt(ss);
    }
  }

  // The TMD spring's alarm: |loss| beyond kappa sd and its smallest size,
  // held for the hold time (latched).
  void device_decide() {
    for (int j = 0; j < d_.np; ++j) {
      if (kind_[j] != static_cast<std::uint8_t>(TwinParam::kDeviceSpring)) continue;
      const S kappa = static_cast<S>(set_[kKappa]), floor = static_cast<S>(set_[kDeviceLossMin]);
      const S thr = kappa * sd_[j] > floor ? kappa * sd_[j] : floor;
      const S size = loss_[j] < S(0) ? -loss_[j] : loss_[j];
      held_[j] = size > thr ? held_[j] + update_steps_ : 0;
      if (held_[j] >= hold_steps_) device_alarm_ = true;
    }
  }

  // The stories' decision (twin/decision.hpp), one part a step after an
  // update so that no step carries it all: the estimate's covariance of the
  // stories (the stories' block of (J + prior)^-1: the device's parameter
  // marginalised), the absolute test, the verdict. The change scan takes
  // the other steps between updates.
  void decision_phase() {
    const int n = d_.stories;
    if (phase_ == 1) {
      S P[kP][kP];
      inverse_from_factor(F_, d_.np, P);
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) sig_[a][b] = P[a][b];
      score_ = score();
      // The misfit: the score beyond what a model that holds gives, held
      // with its memory. The estimate's error is then more than its
      // information says (the first seconds of strong motion, a record the
      // model does not explain): the absolute test's covariance times it.
      const S m = score_ / (static_cast<S>(set_[kMisfitLevel]) * static_cast<S>(d_.np));
      misfit_ *= static_cast<S>(set_[kMisfitForget]);
      if (m > misfit_) misfit_ = m;
    } else if (phase_ == 2) {
      dec_.absolute(loss_, sig_, misfit_ > S(1) ? misfit_ : S(1));
    } else if (phase_ == 3) {
      dec_.decide(update_steps_, score_ > static_cast<S>(set_[kSuspect]));
      if (dec_.take_restart()) {
        const S keep = static_cast<S>(set_[kRestartKeep]);
        for (int a = 0; a < d_.np; ++a)
          for (int b = 0; b <= a; ++b) J_[a][b] *= keep, J0_[a][b] *= keep;
      }
    }
    phase_ = phase_ >= 3 || !factored_ ? 0 : phase_ + 1;
  }
  // The score statistic Gs' Is^-1 Gs (a tenth of the prior's information
  // added, for the first seconds): chi-square with np degrees of freedom
  // while the model holds; a change makes the recent gradients agree.
  S score() const {
    const int np = d_.np;
    S A[kP][kP], u[kP];
    for (int a = 0; a < np; ++a)
      for (int b = 0; b <= a; ++b) A[a][b] = Is_[a][b] + (a == b ? S(0.1) * prior_[a] : S(0));
    if (!cholesky(A, np)) return S(0);
    S t(0);
    for (int a = 0; a < np; ++a) {
      S v = Gs_[a];
      for (int c = 0; c < a; ++c) v -= A[a][c] * u[c];
      u[a] = v / A[a][a];
      t += u[a] * u[a];
    }
    return t;
  }
  DecisionSettings<S> decision_settings() const {
    DecisionSettings<S> c;
    c.threshold = static_cast<S>(set_[kThreshold]);
    c.threshold_change = static_cast<S>(set_[kThresholdChange]);
    c.two = static_cast<S>(set_[kTwoStory]);
    c.two_share = static_cast<S>(set_[kTwoShare]);
    c.separation = static_cast<S>(set_[kSeparation]);
    c.inflation = static_cast<S>(set_[kInflation]);
    c.drift_var = static_cast<S>(set_[kDriftVar]);
    c.snap_steps = static_cast<long>(set_[kSnapSteps]);
    c.hold_steps = hold_steps_;
    c.restart_steps = static_cast<long>(set_[kRestartSteps]);
    c.before_var_max = static_cast<S>(set_[kBeforeVarMax]);
    c.fit_gate = static_cast<S>(set_[kFitGate]);
    return c;
  }

  // state
  S z_[kX] = {}, s_[kP][kX] = {}, a_ = S(0);
  S J_[kP][kP] = {}, g_[kP] = {}, loss_[kP] = {}, sd_[kP] = {};
  S Jc_[Decision<S, N>::kTri] = {}, bc_[kP] = {};  // the change tests' information since the start
  S r2_[kY] = {}, q2_[kY] = {}, eps_[kY] = {};
  long held_[kP] = {};
  long since_ = 0, impact_left_ = 0, k_ = 0, calm_ = 0;
  bool device_alarm_ = false, factored_ = false;
  int phase_ = 0;
  S F_[kP][kP] = {}, sig_[N][N] = {};  // the last factor of J + prior; the stories' covariance
  S J0_[kP][kP] = {}, Is_[kP][kP] = {}, Gs_[kP] = {}, score_ = S(0), lam_update_ = S(1);  // the score
  S misfit_ = S(0);  // the score's excess, held (section 5)
  Decision<S, N> dec_;
};

}  // namespace vines::twin
