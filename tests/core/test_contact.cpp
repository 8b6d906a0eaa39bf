// Contact laws on the paper's Fig. 2 problem: a 5 cm steel sphere hitting a
// fixed rigid wall at 1 m/s (E* = E / (1 - nu^2): the wall does not deform).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <type_traits>

#include "vines/model/bounce.hpp"
#include "vines/model/contact.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/devices.hpp"
#include "vines/model/frame.hpp"
#include "vines/model/frame_presets.hpp"
#include "vines/model/validate.hpp"

namespace {

using namespace vines;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadius = 0.05, kRho = 8000, kE = 210e9, kNu = 0.3, kV = 1.0;

double sphere_mass() { return kRho * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius; }
// Rigid wall: its compliance term vanishes.
double rigid_wall_c() { return contact::hertz_c(kE, kNu, 1e300, 0.0, kRadius); }

TEST(Bounce, KuwabaraWithPaperTauGivesEps070) {
  const double c = rigid_wall_c(), tau = 17.4e-6;
  const BounceResult r = bounce(contact::Kuwabara<double>{c, 1.5 * c * tau}, sphere_mass(), kV);
  ASSERT_TRUE(r.ok);
  EXPECT_NEAR(r.restitution, 0.700, 0.002);
  // Paper: the contact lasts about 0.275 ms.
  EXPECT_NEAR(r.duration, 0.275e-3, 0.01e-3);
}

TEST(Bounce, TsujiGivesItsTargetRestitution) {
  const double c = rigid_wall_c(), m = sphere_mass();
  for (double eps : {0.3, 0.5, 0.7, 0.9, 0.99}) {
    const BounceResult r =
        bounce(contact::Tsuji<double>{c, contact::tsuji_d(eps) * std::sqrt(c * m)}, m, kV);
    ASSERT_TRUE(r.ok);
    EXPECT_NEAR(r.restitution, eps, 1e-6) << "eps " << eps;
  }
}

TEST(Bounce, TsujiRestitutionDoesNotDependOnSpeed) {
  const double c = rigid_wall_c(), m = sphere_mass(), eps = 0.6;
  for (double v : {0.01, 0.1, 10.0}) {
    const BounceResult r =
        bounce(contact::Tsuji<double>{c, contact::tsuji_d(eps) * std::sqrt(c * m)}, m, v);
    EXPECT_NEAR(r.restitution, eps, 1e-6) << "v " << v;
  }
}

TEST(Bounce, HertzConservesEnergyAndMatchesTheContactDuration) {
  const double c = rigid_wall_c(), m = sphere_mass();
  for (double v : {0.1, 1.0, 3.0}) {
    const BounceResult r = bounce(contact::Hertz<double>{c}, m, v);
    ASSERT_TRUE(r.ok);
    // Kinetic energy out / in = restitution^2.
    EXPECT_NEAR(r.restitution * r.restitution, 1.0, 1e-9) << "v " << v;
    // t_c = 3.218 (m/C)^{2/5} v^{-1/5} (coefficient rounded to 4 digits).
    const double tc = 3.218 * std::pow(m / c, 0.4) * std::pow(v, -0.2);
    EXPECT_NEAR(r.duration / tc, 1.0, 2e-4) << "v " << v;
    // Deepest overlap from energy: (5 m v^2 / (4 C))^{2/5}.
    EXPECT_NEAR(r.max_overlap / std::pow(5 * m * v * v / (4 * c), 0.4), 1.0, 1e-6);
  }
}

TEST(Bounce, KuwabaraLosesWhatTheRateTermDissipates) {
  const double c = rigid_wall_c(), m = sphere_mass(), tau = 17.4e-6;
  const BounceResult r = bounce(contact::Kuwabara<double>{c, 1.5 * c * tau}, m, kV);
  const double lost = 0.5 * m * kV * kV * (1.0 - r.restitution * r.restitution);
  EXPECT_NEAR(r.dissipated / lost, 1.0, 1e-8);
}

TEST(Calibration, DefaultParticleTauMatchesModelMd) {
  // docs/model.md section 4.3: eps 0.7 at v_ref 0.5 m/s gives tau = 6.247108475e-4 s for the
  // default particle (5 % of the first-mode effective mass, steel on steel).
  FrameParams fp;
  apply_frame_preset(FramePreset::kTable1, &fp);
  const Modal<10> md = modal_analysis(build_frame<10>(fp));
  const VinesDesign d = design_vines(VinesParams{}, 0.05 * md.m_eff(0), fp.mass_kg[9]);
  EXPECT_NEAR(d.mass, 55.79e3, 0.01e3);
  EXPECT_NEAR(d.radius, 1.1852, 1e-4);
  EXPECT_NEAR(d.box_length, 3.20, 0.005);
  EXPECT_NEAR(d.tau / 6.247108475e-4, 1.0, 1e-9);
  // Round trip: the calibrated tau gives back eps at v_ref.
  const BounceResult r = bounce(contact::Kuwabara<double>{d.c, 1.5 * d.c * d.tau}, d.mass, 0.5);
  EXPECT_NEAR(r.restitution, 0.7, 1e-10);
}

TEST(Calibration, KuwabaraTauFromFig2) {
  // Inverse of the paper's Fig. 2 statement: eps 0.7 at 1 m/s needs tau ~ 17.4 us.
  const double tau = calibrate_kuwabara_tau(rigid_wall_c(), sphere_mass(), 0.7, 1.0);
  EXPECT_NEAR(tau, 17.4e-6, 0.1e-6);
}

TEST(Restitution, ImpulseReversesTheApproachSpeed) {
  const double m1 = 2.0, m2 = 5.0, v = 1.5, eps = 0.6;
  const double j = contact::restitution_impulse(m1, m2, v, eps);
  // Relative speed after = -eps * before; momentum conserved by construction.
  const double dv1 = -j / m1, dv2 = j / m2;
  EXPECT_NEAR((v + dv1 - dv2) / v, -eps, 1e-14);
}

// ---- the registry (contact_laws.hpp)

TEST(ContactLaws, EachLawHasItsPlaceAsCodeAndADistinctName) {
  int place = 0;
  std::set<std::string> names;
  each_law([&](auto law) {
    using L = decltype(law);
    EXPECT_EQ(static_cast<int>(L::kTag), place++);
    EXPECT_STREQ(law_name(L::kTag), L::kName);
    EXPECT_TRUE(names.insert(L::kName).second) << L::kName;
    EXPECT_TRUE((std::is_same_v<LawOf<L::kTag>, L>));
  });
  EXPECT_EQ(place, kContactLawCount);
  const ContactLaw unknown = static_cast<ContactLaw>(kContactLawCount);
  EXPECT_EQ(law_name(unknown), nullptr);
  EXPECT_FALSE(with_law(unknown, [](auto) {}));
}

TEST(ContactLaws, AnUnknownLawCodeIsRefusedByValidation) {
  DeviceParams d;
  d.kind = DeviceKind::kVines;
  d.vines.law = static_cast<ContactLaw>(kContactLawCount);
  const ParamError e = validate(d, 10);
  ASSERT_FALSE(e.ok());
  EXPECT_STREQ(e.field, "vines.law");
}

}  // namespace
