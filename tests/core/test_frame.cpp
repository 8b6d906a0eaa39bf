// The shear frame, its modal analysis and the TMD design against
// docs/model.md sections 2 and 3 and the paper's Table 1.
#include <gtest/gtest.h>

#include <cmath>

#include "vines/model/devices.hpp"
#include "vines/model/frame.hpp"
#include "vines/model/frame_presets.hpp"

namespace {

using namespace vines;

Frame<10> preset_frame(FramePreset p) {
  FrameParams fp;
  apply_frame_preset(p, &fp);
  return build_frame<10>(fp);
}

TEST(Frame, Table1FirstModeMatchesModelMd) {
  const Modal<10> md = modal_analysis(preset_frame(FramePreset::kTable1));
  EXPECT_NEAR(md.frequency_hz()(0), 0.4946, 5e-5);
  EXPECT_NEAR(md.zeta(0), 0.0200, 5e-5);
  EXPECT_NEAR(md.m_eff(0), 1115.9e3, 0.05e3);
  EXPECT_NEAR(md.m_eff(0) / md.m_eff.sum(), 0.806, 5e-4);
  // Highest mode: 5.8 Hz (docs/model.md sections 2 and 12).
  EXPECT_NEAR(md.frequency_hz()(9), 5.8, 0.05);
}

TEST(Frame, ModesAreMassOrthonormalAndDiagonaliseKAndC) {
  const Frame<10> f = preset_frame(FramePreset::kTable1);
  const Modal<10> md = modal_analysis(f);
  const Eigen::Matrix<double, 10, 10> mm = md.phi.transpose() * f.m.asDiagonal() * md.phi;
  EXPECT_LT((mm - Eigen::Matrix<double, 10, 10>::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::Matrix<double, 10, 10> kk = md.phi.transpose() * f.K * md.phi;
  for (int j = 0; j < 10; ++j) {
    EXPECT_NEAR(kk(j, j) / (md.omega(j) * md.omega(j)), 1.0, 1e-12);
    kk(j, j) = 0.0;
  }
  EXPECT_LT(kk.cwiseAbs().maxCoeff(), 1e-9 * md.omega(9) * md.omega(9));
  EXPECT_NEAR(md.m_eff.sum() / f.m.sum(), 1.0, 1e-12);
}

TEST(Frame, Sadek1997MatchesThePapersModeShapeColumn) {
  // docs/model.md section 11 (E3): Table 1's normalised first mode matches k2 = 59.26 MN/m. The
  // column is the shape scaled by its participation factor.
  const Modal<10> md = modal_analysis(preset_frame(FramePreset::kSadek1997));
  const double table[10] = {0.175, 0.355, 0.534, 0.708, 0.871, 1.019, 1.146, 1.248, 1.321, 1.359};
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(md.phi(i, 0) * md.gamma(0), table[i], 1.5e-3) << i;
}

TEST(Frame, RayleighAndModalDampingHitTheirTargets) {
  FrameParams fp;
  apply_frame_preset(FramePreset::kTable1, &fp);
  fp.damping = DampingRule::kRayleigh;
  fp.rayleigh_zeta[0] = 0.02;
  fp.rayleigh_zeta[1] = 0.05;
  fp.rayleigh_modes[0] = 1;
  fp.rayleigh_modes[1] = 4;
  Modal<10> md = modal_analysis(build_frame<10>(fp));
  EXPECT_NEAR(md.zeta(0), 0.02, 1e-12);
  EXPECT_NEAR(md.zeta(3), 0.05, 1e-12);
  fp.damping = DampingRule::kModal;
  fp.modal_zeta = 0.03;
  md = modal_analysis(build_frame<10>(fp));
  for (int j = 0; j < 10; ++j) EXPECT_NEAR(md.zeta(j), 0.03, 1e-12) << j;
}

TEST(Frame, DamageScalesFrequenciesBySqrtEta) {
  FrameParams fp;
  apply_frame_preset(FramePreset::kTable1, &fp);
  const double f1 = modal_analysis(build_frame<10>(fp)).frequency_hz()(0);
  fp.stiffness_scale = 0.7;
  EXPECT_NEAR(modal_analysis(build_frame<10>(fp)).frequency_hz()(0) / f1, std::sqrt(0.7), 1e-12);
}

TEST(Tmd, DenHartogDesignForFivePercent) {
  const Modal<10> md = modal_analysis(preset_frame(FramePreset::kTable1));
  const TmdDesign d = design_tmd(TmdParams{}, 0.05 * md.m_eff(0), md.m_eff(0), md.omega(0));
  EXPECT_NEAR(d.lambda, 0.9524, 5e-5);
  EXPECT_NEAR(d.xi, 0.1336, 5e-5);
  EXPECT_NEAR(d.mass, 55.79e3, 0.01e3);
  EXPECT_NEAR(d.omega / md.omega(0), d.lambda, 1e-12);
  EXPECT_NEAR(d.c / (2 * d.mass * d.omega), d.xi, 1e-12);
}

}  // namespace
