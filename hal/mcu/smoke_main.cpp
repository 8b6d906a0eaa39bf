// MCU smoke image: runs a piece of the firmware core in the target's scalar
// (float on the Cortex-M4F FPU) and reports through semihosting. Exit status
// 0 = pass. It must stay heap-free: the link fails otherwise (mcu_image.cmake).
//
// Layout: run_smoke() does the work and returns nullptr on success or a
// message naming the failed check; main() only reports. To smoke-test the
// simulation instead, replace the body of run_smoke() (e.g. build the model
// from the preset scene with vines/sim.hpp and advance it a few steps,
// checking the result), keeping that contract.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstring>

#include "semihost.h"
#include "vines/frame_presets.hpp"
#include "vines/params.hpp"
#include "vines/validate.hpp"

namespace {

using Scalar = VINES_MCU_SCALAR;  // float (cmake/arm-none-eabi-cortex-m4f.cmake)
constexpr int kStories = 10;
using Matrix = Eigen::Matrix<Scalar, kStories, kStories>;
constexpr double kPi = 3.14159265358979323846;

// First and last natural frequencies [Hz] of the table-1 frame (computed in
// double precision on the host).
constexpr double kF1Hz = 0.4945950, kF10Hz = 5.7761721;

bool near(double x, double want, double rel) { return std::fabs(x - want) <= rel * want; }

const char* run_smoke(double* f1_hz) {
  vines::SceneParams scene;  // defaults: no device, 1 kHz loop
  vines::apply_frame_preset(vines::FramePreset::kTable1, &scene.frame);
  if (!vines::validate(scene).ok()) return "table-1 scene refused by validate()";

  vines::SceneParams bad = scene;  // the checks must also refuse
  bad.frame.mass_kg[3] = 0.0;
  const vines::ParamError e = vines::validate(bad);
  if (e.ok() || std::strcmp(e.field, "frame.masses") != 0 || e.index != 3)
    return "zero mass not refused as frame.masses[3]";

  // Mass-normalised shear-frame stiffness A = M^-1/2 K M^-1/2; eig(A) = w^2.
  const vines::FrameParams& f = scene.frame;
  Matrix k = Matrix::Zero();
  for (int i = 0; i < kStories; ++i) {
    const auto ki = static_cast<Scalar>(f.stiffness_n_per_m[i] * f.stiffness_scale);
    k(i, i) += ki;
    if (i > 0) {
      k(i - 1, i - 1) += ki;
      k(i - 1, i) = k(i, i - 1) = -ki;
    }
  }
  Eigen::Matrix<Scalar, kStories, 1> inv_sqrt_m;
  for (int i = 0; i < kStories; ++i)
    inv_sqrt_m(i) = static_cast<Scalar>(1.0 / std::sqrt(f.mass_kg[i]));
  const Matrix a = inv_sqrt_m.asDiagonal() * k * inv_sqrt_m.asDiagonal();

  const Eigen::SelfAdjointEigenSolver<Matrix> eig(a);
  if (eig.info() != Eigen::Success) return "eigensolver did not converge";
  const auto w2 = eig.eigenvalues();
  for (int i = 0; i < kStories; ++i)
    if (!(w2(i) > 0 && (i == 0 || w2(i) > w2(i - 1))))
      return "eigenvalues not positive and increasing";
  const Matrix vtv = eig.eigenvectors().transpose() * eig.eigenvectors();
  if (!vtv.isIdentity(Scalar(1e-4))) return "mode shapes not orthonormal";

  *f1_hz = std::sqrt(static_cast<double>(w2(0))) / (2 * kPi);
  const double f10_hz = std::sqrt(static_cast<double>(w2(kStories - 1))) / (2 * kPi);
  if (!near(*f1_hz, kF1Hz, 1e-4) || !near(f10_hz, kF10Hz, 1e-4))
    return "natural frequencies off the double-precision values";
  return nullptr;
}

}  // namespace

int main() {
  double f1_hz = 0.0;
  if (const char* failure = run_smoke(&f1_hz)) {
    vines_semihost_puts("vines mcu smoke: FAIL: ");
    vines_semihost_puts(failure);
    vines_semihost_puts("\n");
    return 1;
  }
  vines_semihost_puts("vines mcu smoke: ok (f1 = ");
  vines_semihost_put_int(std::llround(f1_hz * 1e6));
  vines_semihost_puts(" uHz)\n");
  return 0;
}
