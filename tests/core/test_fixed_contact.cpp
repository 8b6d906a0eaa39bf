// The contact laws in fixed point (vines/fixed/contact.hpp, fixed/bounce.hpp):
// every law of the registry, its kernel scaled to the units of a contact,
// against the same kernel in double, and the paper's Fig. 2 bounce in Q3.28
// against the double bounce (bounce.hpp, adaptive Dormand-Prince, rtol
// 1e-13) and against the energy balance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "vines/fixed/bounce.hpp"
#include "vines/fixed/contact.hpp"
#include "vines/model/bounce.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/devices.hpp"
#include "vines/numeric/fixed.hpp"

namespace {

using namespace vines;
using Q = numeric::Fixed<28>;

// A 5 cm steel sphere against a steel wall on a floor 1e12 times heavier:
// the paper's Fig. 2 sphere, each law's design (Kuwabara: tau calibrated to
// eps 0.7 at v_ref 0.5 m/s; Tsuji: eps 0.7).
VinesDesign fig2_design(ContactLaw law) {
  VinesParams p;
  p.law = law;
  p.radius_m = 0.05;
  return design_vines(p, 0.0, 1e12 * 4.19);
}

// Calls f(Law, design) for every law with a finite-duration contact.
template <typename F>
void each_contact_law(F&& f) {
  each_law([&](auto law) {
    using L = decltype(law);
    if constexpr (!L::kImpulsive) f(law, fig2_design(L::kTag));
  });
}

// The scaled kernel in double gives the physical force in units of
// m V^2 / D, and the elastic force of the elastic impact at V peaks at 5/4.
TEST(FixedContact, ScaledKernelIsTheForceInContactUnits) {
  each_contact_law([](auto law, const VinesDesign& d) {
    using L = decltype(law);
    const auto k = L::template kernel<double>(d);
    const fixed::ContactUnits u = fixed::contact_units(d.mass, d.c, d.v_ref);
    const auto ks = fixed::scaled_kernel<double>(k, u);
    for (double x : {0.01, 0.3, 1.0, 1.2}) {
      for (double rate : {-1.0, -0.2, 0.0, 0.7, 1.0}) {
        const double q = std::sqrt(std::sqrt(x * u.d));
        const double want = k.regular(q, rate * u.v).total() / u.force();
        const double got = ks.regular(std::sqrt(std::sqrt(x)), rate).total();
        EXPECT_NEAR(got, want, 1e-12 * (1.0 + std::fabs(want))) << L::kName << " x " << x << " rate " << rate;
      }
    }
    EXPECT_NEAR(ks.regular(1.0, 0.0).elastic, 1.25, 1e-12) << L::kName;
  });
}

// In Q3.28 the force's error is absolute against its peak (5/4): a few
// units of 2^-28 over the whole contact (q^ in [0, 1.1], u in [-1, 1]).
TEST(FixedContact, ForceErrorIsAbsoluteAgainstThePeak) {
  each_contact_law([](auto law, const VinesDesign& d) {
    using L = decltype(law);
    const fixed::ContactUnits u = fixed::contact_units(d.mass, d.c, d.v_ref);
    const auto kd = fixed::scaled_kernel<double>(L::template kernel<double>(d), u);
    const auto kq = fixed::scaled_kernel<Q>(L::template kernel<double>(d), u);
    double worst = 0;
    for (int i = 0; i <= 220; ++i) {
      for (int j = -20; j <= 20; ++j) {
        const Q q(i / 200.0), rate(j / 20.0);
        const double want = kd.regular(static_cast<double>(q), static_cast<double>(rate)).total();
        worst = std::fmax(worst, std::fabs(static_cast<double>(kq.regular(q, rate).total()) - want));
      }
    }
    std::printf("%s: largest force error %.3g (units of m V^2 / D; peak 1.25), %.1f ulps of Q3.28\n", L::kName,
                worst, worst * Q::kOne);
    EXPECT_LT(worst, 16.0 / Q::kOne);
  });
}

// The bounce in Q3.28 at impact speeds 0.25, 0.5 and 1 V (V bounds them): restitution and
// duration against the double bounce, the energy lost against the rebound.
TEST(FixedContact, BounceMatchesDoubleAndItsEnergyBalance) {
  numeric::fixed_saturations() = 0;
  each_contact_law([](auto law, const VinesDesign& d) {
    using L = decltype(law);
    const auto kd = L::template kernel<double>(d);
    const fixed::ContactUnits u = fixed::contact_units(d.mass, d.c, d.v_ref);
    const auto kq = fixed::scaled_kernel<Q>(kd, u);
    for (double u0 : {0.25, 0.5, 1.0}) {
      const BounceResult ref = bounce(kd, d.mass, u0 * u.v);
      const fixed::FixedBounce<Q> r = fixed::bounce_fixed(kq, Q(u0));
      ASSERT_TRUE(ref.ok && r.ok) << L::kName << " u0 " << u0;
      const double eps = static_cast<double>(r.restitution), dur = static_cast<double>(r.duration) * u.t;
      const double lost = static_cast<double>(r.dissipated), balance = 0.5 * u0 * u0 * (1.0 - eps * eps);
      std::printf("%s u0 %.2f: eps %.9f (double %.9f), duration %.6e s (double %.6e s), lost %.7f "
                  "(from the rebound %.7f), %d steps\n",
                  L::kName, u0, eps, ref.restitution, dur, ref.duration, lost, balance, r.steps);
      EXPECT_NEAR(eps, ref.restitution, 2e-6) << L::kName << " u0 " << u0;
      EXPECT_NEAR(dur / ref.duration, 1.0, 1e-6) << L::kName << " u0 " << u0;
      EXPECT_NEAR(lost, balance, 2e-6) << L::kName << " u0 " << u0;
    }
  });
  EXPECT_EQ(numeric::fixed_saturations(), 0u);
}

}  // namespace
