// The twin's decision (twin/hypotheses.hpp, twin/decision.hpp) against
// independent computations: the one- and two-story GLRT statistics and
// sizes by generalised least squares in Eigen, and the absolute test and
// the change scan on a synthetic linear estimator (a step in one story, a
// model error that cancels, none, two stories, a loss before the record).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "vines/twin/decision.hpp"

namespace {

using vines::twin::Decision;
using vines::twin::DecisionSettings;
using vines::twin::Hypotheses;
constexpr int N = 10;

// An AR(1)-correlated covariance with alternating signs, as the stories'
// estimates have around unmeasured floors.
Eigen::MatrixXd covariance(int n, double sd, double rho) {
  Eigen::MatrixXd S(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) S(a, b) = sd * sd * std::pow(-rho, std::abs(a - b)) * (1 + 0.1 * (a == b) * a);
  return S;
}

// The GLRT of hypothesis "the stories in `which` changed" against none, in
// Eigen: theta' W theta - min over sizes of the residual's weighted norm.
double glrt(const Eigen::MatrixXd& S, const Eigen::VectorXd& th, const std::vector<int>& which, Eigen::VectorXd* size) {
  const Eigen::MatrixXd W = S.inverse();
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(th.size(), static_cast<int>(which.size()));
  for (std::size_t i = 0; i < which.size(); ++i) E(which[i], static_cast<int>(i)) = 1;
  *size = (E.transpose() * W * E).ldlt().solve(E.transpose() * W * th);
  const Eigen::VectorXd r = th - E * *size;
  return th.dot(W * th) - r.dot(W * r);
}

TEST(TwinDecision, HypothesesMatchGeneralisedLeastSquares) {
  const Eigen::MatrixXd S = covariance(N, 0.01, 0.6);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit;
  for (int draw = 0; draw < 20; ++draw) {
    Eigen::VectorXd th(N);
    for (int j = 0; j < N; ++j) th(j) = 0.01 * unit(rng);
    th(draw % N) += 0.08;
    double A[N][N], P[N][N], t[N];
    for (int a = 0; a < N; ++a) {
      t[a] = th(a);
      for (int b = 0; b < N; ++b) A[a][b] = S(a, b);
    }
    ASSERT_TRUE(vines::twin::cholesky(A, N));
    vines::twin::inverse_from_factor(A, N, P);
    Hypotheses<double, N> h;
    vines::twin::test_hypotheses(P, t, N, &h);
    double best = 0, best_two = 0;
    for (int j = 0; j < N; ++j) {
      Eigen::VectorXd d;
      const double T = glrt(S, th, {j}, &d);
      EXPECT_NEAR(h.size[j], d(0), 1e-12) << j;
      EXPECT_NEAR(h.stat[j], d(0) > 0 ? T : 0.0, 1e-9 * (1 + T)) << j;
      if (d(0) > 0) best = std::max(best, T);
      for (int k = j + 1; k < N; ++k) {
        const double T2 = glrt(S, th, {j, k}, &d);
        if (d(0) > 0 && d(1) > 0) best_two = std::max(best_two, T2);
      }
    }
    EXPECT_NEAR(h.one, best, 1e-9 * (1 + best));
    EXPECT_NEAR(h.two, best_two, 1e-9 * (1 + best_two));
    EXPECT_EQ(h.story, draw % N) << "a loss of over 5 sd: its story first";
  }
}

// A synthetic estimator on a linear model: four channels a step, each
// y = psi' (theta + bias) + unit noise with psi random (the information of
// 10 s is some 40,000 a story: estimates to about 0.5 %), bias the model's
// error, the same before and after an onset. What the estimator hands the
// decision: the losses and their covariance, a least-squares fit with 20 s
// of memory (the absolute test), and the information and right-hand side
// summed since the start (the change scan), scanned a few parts a step as
// the node spreads it.
struct Synthetic {
  double scale = 7.0;
  double misfit = 1.0;  // the estimator's misfit the absolute test is told of
  double run(Decision<double, N>* d, const double (&before)[N], const double (&after)[N], const double (&bias)[N],
             double onset, double T, std::uint64_t seed) const {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> unit;
    constexpr int kTri = Decision<double, N>::kTri;
    double Jc[kTri] = {}, bc[N + 1] = {}, loss[N] = {}, sig[N][N] = {};
    Eigen::MatrixXd Jf = Eigen::MatrixXd::Zero(N, N);
    Eigen::VectorXd bf = Eigen::VectorXd::Zero(N);
    const double h = 0.05, lam = std::exp(-h / 20.0);
    double detect = -1;
    for (long k = 0; k * h < T; ++k) {
      const double t = k * h;
      Jf *= lam, bf *= lam;
      for (int i = 0; i < 4; ++i) {
        Eigen::VectorXd psi(N);
        double y = unit(rng);
        for (int a = 0; a < N; ++a) {
          psi(a) = scale * unit(rng);
          y += psi(a) * ((t < onset ? before[a] : after[a]) + bias[a]);
        }
        Jf += psi * psi.transpose(), bf += psi * y;
        for (int a = 0; a < N; ++a) {
          bc[a] += psi(a) * y;
          for (int b = 0; b <= a; ++b) Jc[vines::twin::tri(a, b)] += psi(a) * psi(b);
        }
      }
      const Eigen::MatrixXd P = (Jf + Eigen::MatrixXd::Identity(N, N) * 25.0).inverse();
      const Eigen::VectorXd th = P * bf;
      for (int a = 0; a < N; ++a) {
        loss[a] = th(a);
        for (int b = 0; b < N; ++b) sig[a][b] = P(a, b);
      }
      d->observe(k, loss, Jc, bc);
      d->absolute(loss, sig, misfit);
      for (int part = 0; part < 9; ++part) d->scan(Jc, bc);
      d->decide(1);
      if (detect < 0 && d->detected()) detect = t;
    }
    return detect;
  }
};

DecisionSettings<double> settings() {
  DecisionSettings<double> s;
  s.threshold = 25, s.threshold_change = 36, s.two = 10.8, s.separation = 4, s.inflation = 1, s.drift_var = 1e-6;
  s.snap_steps = 20;  // one a second at 20 updates a second
  s.hold_steps = 40;  // 2 s
  s.fit_gate = 27.877;  // chi-square, 9 degrees of freedom, 0.1 % (scipy.stats.chi2.isf(0.001, 9))
  return s;
}

constexpr double kPrior[N + 1] = {25, 25, 25, 25, 25, 25, 25, 25, 25, 25, 25};  // sd 0.2

TEST(TwinDecision, ChangeDuringTheRecordFoundWithItsOnset) {
  // The healthy building is 2 % off its drawing in every story (the model's
  // error the absolute test is told of: 3 % sd), then story 4 loses 5 %.
  double base[N] = {}, sigma0[N][N] = {}, before[N], after[N], bias[N] = {};
  for (int a = 0; a < N; ++a) sigma0[a][a] = 0.03 * 0.03, before[a] = after[a] = a % 2 ? 0.02 : -0.02;
  after[3] += 0.05;
  int dated = 0;  // onsets within 2 s
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    Decision<double, N> d;
    d.init(N, N, settings(), base, sigma0, kPrior);
    const double detect = Synthetic{}.run(&d, before, after, bias, 30.0, 60.0, seed);
    ASSERT_TRUE(d.detected()) << seed;
    EXPECT_EQ(d.story(), 4) << seed;
    EXPECT_NEAR(d.size(), 0.05, 0.01) << seed;
    const double onset = static_cast<double>(d.onset_step()) * 0.05;
    EXPECT_NEAR(onset, 30.0, 6.0) << seed;
    dated += std::abs(onset - 30.0) <= 2.0;
    EXPECT_GT(detect, 30.0) << seed;
    EXPECT_LT(detect, 45.0) << seed;
  }
  EXPECT_GE(dated, 9);  // the one seed found late (at 40 s, weak evidence) dates it at 36 s
}

TEST(TwinDecision, ModelErrorCancelsInTheChange) {
  // The model errs by 4 % in alternating signs (beyond the absolute test's
  // threshold on its own), the same before and after a 5 % loss of story 7:
  // the change scan names story 7 and sizes the change alone.
  double base[N] = {}, sigma0[N][N] = {}, before[N] = {}, after[N] = {}, bias[N];
  for (int a = 0; a < N; ++a) sigma0[a][a] = 1.0, bias[a] = a % 2 ? 0.04 : -0.04;  // the absolute test silenced
  after[6] = 0.05;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    Decision<double, N> d;
    d.init(N, N, settings(), base, sigma0, kPrior);
    Synthetic{}.run(&d, before, after, bias, 25.0, 50.0, seed);
    ASSERT_TRUE(d.detected()) << seed;
    EXPECT_EQ(d.story(), 7) << seed;
    EXPECT_NEAR(d.size(), 0.05, 0.01) << seed;
  }
}

TEST(TwinDecision, ChangeVerdictStandsAgainstTheAbsoluteTest) {
  // Story 4 is 3 % softer than its drawing (the absolute test is told of
  // 0.8 %): when it loses 10 % of what it had, the absolute test reads 12.7 %
  // from the drawing and, once the onset has left the change scan's span,
  // is the stronger test. The verdict stays the change test's: 10 % of the
  // story's stiffness before, dated at the onset.
  double base[N] = {}, sigma0[N][N] = {}, before[N] = {}, after[N] = {}, bias[N] = {};
  for (int a = 0; a < N; ++a) sigma0[a][a] = 0.008 * 0.008;
  before[3] = 0.03;
  after[3] = 1 - (1 - before[3]) * 0.90;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    Decision<double, N> d;
    d.init(N, N, settings(), base, sigma0, kPrior);
    Synthetic{}.run(&d, before, after, bias, 30.0, 75.0, seed);
    ASSERT_TRUE(d.detected()) << seed;
    EXPECT_EQ(d.story(), 4) << seed;
    EXPECT_NEAR(d.size(), 0.10, 0.01) << seed;
    EXPECT_NEAR(static_cast<double>(d.onset_step()) * 0.05, 30.0, 2.0) << seed;
  }
}

TEST(TwinDecision, HealthyBuildingOffItsDrawingRaisesNoAlarm) {
  double base[N] = {}, sigma0[N][N] = {}, before[N], bias[N] = {};
  for (int a = 0; a < N; ++a) sigma0[a][a] = 0.03 * 0.03, before[a] = a % 2 ? 0.02 : -0.02;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    Decision<double, N> d;
    d.init(N, N, settings(), base, sigma0, kPrior);
    Synthetic{}.run(&d, before, before, bias, 1e9, 60.0, seed);
    EXPECT_FALSE(d.detected()) << seed;
  }
}

TEST(TwinDecision, TwoStoriesNamedBoth) {
  double base[N] = {}, sigma0[N][N] = {}, before[N] = {}, after[N] = {}, bias[N] = {};
  for (int a = 0; a < N; ++a) sigma0[a][a] = 0.03 * 0.03;
  after[1] = after[6] = 0.10;
  Decision<double, N> d;
  d.init(N, N, settings(), base, sigma0, kPrior);
  Synthetic{}.run(&d, before, after, bias, 20.0, 50.0, 7);
  ASSERT_TRUE(d.detected());
  EXPECT_EQ(d.story(), 2);
  EXPECT_EQ(d.second_story(), 7);
  EXPECT_NEAR(d.size(), 0.10, 0.01);
  EXPECT_NEAR(d.second_size(), 0.10, 0.01);
}

TEST(TwinDecision, LossBeforeTheRecordFoundAgainstTheBaseline) {
  // A commissioned baseline knows the healthy building to 0.5 %: a 5 % loss
  // from the start is found by the absolute test (no onset to scan for).
  double base[N], sigma0[N][N] = {}, before[N], after[N], bias[N] = {};
  for (int a = 0; a < N; ++a) base[a] = before[a] = after[a] = a % 2 ? 0.02 : -0.02, sigma0[a][a] = 0.005 * 0.005;
  after[7] += 0.05;
  Decision<double, N> d;
  d.init(N, N, settings(), base, sigma0, kPrior);
  Synthetic{}.run(&d, before, after, bias, 0.0, 40.0, 11);
  ASSERT_TRUE(d.detected());
  EXPECT_EQ(d.story(), 8);
  EXPECT_NEAR(d.size(), 0.05, 0.01);
}

TEST(TwinDecision, EstimateNoHypothesisExplainsRaisesNoAlarm) {
  // The estimates err in alternating signs by 8 % where their covariance
  // claims 0.5 % (a record the model does not explain): the best story's
  // statistic is far beyond the threshold, and what it leaves unexplained
  // far beyond the chi-square gate. With the gate, no alarm; without it,
  // one. A single 5 % loss passes it (LossBeforeTheRecordFoundAgainstTheBaseline).
  double base[N] = {}, sigma0[N][N] = {}, before[N], bias[N] = {};
  for (int a = 0; a < N; ++a) before[a] = a % 2 ? 0.08 : -0.08, sigma0[a][a] = 0.005 * 0.005;
  for (double gate : {27.877, 1e30}) {
    DecisionSettings<double> s = settings();
    s.fit_gate = gate;
    Decision<double, N> d;
    d.init(N, N, s, base, sigma0, kPrior);
    Synthetic{}.run(&d, before, before, bias, 1e9, 40.0, 5);
    EXPECT_EQ(d.detected(), gate > 1e6) << gate;
  }
}

TEST(TwinDecision, MisfitWidensTheAbsoluteTest) {
  // The same loss before the record, the estimator reporting a misfit: its
  // estimate's covariance 100 times wider (sd 10 times, about 5 %), the 5 %
  // loss is within it and raises no alarm; a misfit of 1 is the test above.
  double base[N], sigma0[N][N] = {}, before[N], after[N], bias[N] = {};
  for (int a = 0; a < N; ++a) base[a] = before[a] = after[a] = a % 2 ? 0.02 : -0.02, sigma0[a][a] = 0.005 * 0.005;
  after[7] += 0.05;
  for (double misfit : {1.0, 100.0}) {
    Decision<double, N> d;
    d.init(N, N, settings(), base, sigma0, kPrior);
    Synthetic run;
    run.misfit = misfit;
    run.run(&d, before, after, bias, 0.0, 40.0, 11);
    EXPECT_EQ(d.detected(), misfit == 1.0) << misfit;
  }
}

}  // namespace
