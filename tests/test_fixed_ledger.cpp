// The energy ledger in fixed point (firmware/include/vines/fixed/ledger.hpp)
// as `vines run` keeps it: the balance of the bare frame and of the VI NES
// on the shipped El Centro scenes, each turned to fixed point, against the
// same scene's double ledger (the split scheme). The bare frame is linear:
// its ledger follows double's closely; the VI NES is chaotic: one draw's
// entries differ as its E_r does, and the balance itself is the check.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"
#include "scene_support.hpp"
#include "support.hpp"

namespace {

using namespace vines;
using namespace vines::host;

using scene_test::kScenes;

// A shipped scene (its energy_ledger = true) with loop lines put first.
RunReport run_with(const std::string& file, const std::string& loop_lines) {
  const Scene scene = parse_scene(scene_test::shipped_scene_with(file, loop_lines), kScenes + file);
  EXPECT_TRUE(scene.params.loop.energy_ledger) << file;
  return run_scene(scene, RunOptions{});
}

const std::string kSplit = "contact_scheme = \"split\"\n";
const std::string kFixed = kSplit + "scalar = \"fixed\"\nfixed_accel_mps2 = 3.5\n";

void print(const char* what, const Ledger& f, const Ledger& d) {
  std::printf("%s: residual %.2e (double %.2e); input %.6e J (%.6e), damping %.6e (%.6e), contacts %.6e (%.6e), "
              "stored %.4e (%.4e)\n",
              what, f.relative_residual(), d.relative_residual(), f.input, d.input, f.damping, d.damping, f.contact,
              d.contact, f.kinetic + f.strain + f.device, d.kinetic + d.strain + d.device);
}

TEST(FixedLedger, BareFrameBalancesAsDoubleDoes) {
  const RunReport f = run_with("elcentro_bare.toml", "scalar = \"fixed\"\n");
  const RunReport d = run_with("elcentro_bare.toml", "");
  const Ledger& lf = f.totals.ledger;
  const Ledger& ld = d.totals.ledger;
  print("bare frame", lf, ld);
  EXPECT_EQ(f.status.name(), std::string("ok")) << f.status.codes();
  EXPECT_EQ(f.totals.fixed_saturations, 0);
  // The residual is the fixed step's own rounding (its quadrature's error
  // is below 1e-6): 8.7e-6 with units scaled for 3.5 m/s^2, 2.8e-5 at the
  // scene's 1 g, 4.6e-5 at 30 m/s^2 (double's exact step integrals: 2e-13).
  EXPECT_LT(lf.relative_residual(), 5e-5);
  EXPECT_NEAR(lf.input, ld.input, 1e-4 * ld.input);
  EXPECT_NEAR(lf.damping, ld.damping, 1e-4 * ld.damping);
  EXPECT_EQ(lf.contact, 0.0);
  EXPECT_NEAR(lf.kinetic + lf.strain, ld.kinetic + ld.strain, 1e-4 * ld.max_input);
}

TEST(FixedLedger, VinesBalancesOnEveryLaw) {
  for (const char* file : {"elcentro_vines.toml", "elcentro_vines_hertz.toml", "elcentro_vines_tsuji.toml"}) {
    const RunReport f = run_with(file, kFixed);
    const RunReport d = run_with(file, kSplit);
    const Ledger& lf = f.totals.ledger;
    const Ledger& ld = d.totals.ledger;
    print(file, lf, ld);
    EXPECT_EQ(f.status.name(), std::string("ok")) << file << ": " << f.status.codes();
    EXPECT_EQ(f.totals.fixed_saturations, 0) << file;
    EXPECT_LT(lf.relative_residual(), 3e-5) << file;  // double's split: 0.9e-6 to 3.1e-6
    // One chaotic draw: the contacts' share of the input within a few points.
    EXPECT_NEAR(lf.input, ld.input, 0.05 * ld.input) << file;
    EXPECT_NEAR(lf.contact / lf.input, ld.contact / ld.input, 0.03) << file;
    if (std::string(file).find("hertz") != std::string::npos) EXPECT_EQ(lf.contact, 0.0) << file;  // elastic
    else EXPECT_GT(lf.contact, 0) << file;
  }
}

}  // namespace
