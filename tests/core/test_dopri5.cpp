// The Dormand-Prince step and its dense output against the exact solution of
// a harmonic oscillator: the step's error falls as h^6 (order 5), the dense
// output's inside the step as h^5 (order 4), and the dense output meets the
// step at both ends.
#include <cmath>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "vines/numeric/dopri5.hpp"

namespace {

using Vec = Eigen::Matrix<double, 2, 1>;

// y'' = -y from (1, 0): y = cos t, y' = -sin t.
struct Oscillator {
  Vec operator()(double, const Vec& y) const { return Vec(y(1), -y(0)); }
};

Vec exact(double t) { return Vec(std::cos(t), -std::sin(t)); }

// Largest error of the dense output over 9 points inside a step of length h
// (from t0 = 0.3), and the step's own error at its end.
void errors(double h, double* dense, double* step) {
  const Oscillator rhs;
  const double t0 = 0.3;
  const Vec y0 = exact(t0), f0 = rhs(t0, y0);
  const auto r = vines::numeric::dopri5_step<Vec>(rhs, t0, y0, f0, h);
  const auto d = vines::numeric::dopri5_dense(r, y0, f0, h);
  *dense = 0;
  for (int i = 1; i < 10; ++i) {
    const double th = i / 10.0;
    *dense = std::fmax(*dense, (d.at(th) - exact(t0 + th * h)).cwiseAbs().maxCoeff());
  }
  *step = (r.y - exact(t0 + h)).cwiseAbs().maxCoeff();
}

TEST(Dopri5, StepAndDenseOutputConvergeAtTheirOrders) {
  double dense1, step1, dense2, step2;
  errors(0.2, &dense1, &step1);
  errors(0.1, &dense2, &step2);
  // Halving h: the step's local error by 2^6 = 64, the dense output's by 2^5 = 32.
  EXPECT_NEAR(std::log2(step1 / step2), 6.0, 0.3);
  EXPECT_NEAR(std::log2(dense1 / dense2), 5.0, 0.3);
  EXPECT_LT(dense2, 1e-8);
}

TEST(Dopri5, DenseOutputMeetsTheStepAtBothEnds) {
  const Oscillator rhs;
  const Vec y0 = exact(1.0), f0 = rhs(1.0, y0);
  const double h = 0.4;
  const auto r = vines::numeric::dopri5_step<Vec>(rhs, 1.0, y0, f0, h);
  const auto d = vines::numeric::dopri5_dense(r, y0, f0, h);
  EXPECT_EQ((d.at(0.0) - y0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT((d.at(1.0) - r.y).cwiseAbs().maxCoeff(), 1e-15);
  // Its slope at the ends is the derivative there (central difference).
  const double e = 1e-6;
  const Vec slope0 = (d.at(e) - d.at(-e)) / (2 * e * h), slope1 = (d.at(1 + e) - d.at(1 - e)) / (2 * e * h);
  EXPECT_LT((slope0 - f0).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT((slope1 - r.f).cwiseAbs().maxCoeff(), 1e-8);
}

}  // namespace
