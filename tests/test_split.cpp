// The split contact scheme (loop.contact_scheme = "split", substep_split.hpp):
// accuracy against the converged reference (data/reference, DOP853 in long
// double) for each law with a contact duration, convergence in
// loop.split_steps, float, the IC grid's rate (50 Hz) and an ensemble of
// initial conditions against the adaptive scheme, the work bound on every
// step, and the refusals of its scene keys and link fields.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>


#include "sim_host/scene/scene.hpp"
#include "reference_support.hpp"
#include "scene_support.hpp"
#include "support.hpp"
#include "vines/link/config.hpp"
#include "vines/model/devices.hpp"

namespace {

using namespace vines;

const int kSteps = LoopParams{}.split_steps;

using test::reference;
using test::rel;

SceneParams split_scene(ContactLaw law = ContactLaw::kKuwabara, double rate_hz = 1000.0, int steps = kSteps) {
  SceneParams p = test::paper_scene(DeviceKind::kVines, law, rate_hz);
  p.loop.contact_scheme = ContactScheme::kSplit;
  p.loop.split_steps = steps;
  return p;
}

double bare_peak(const SceneParams& p, const std::vector<double>& a, host::Scalar scalar = host::Scalar::kDouble) {
  SceneParams bare = p;
  bare.device.kind = DeviceKind::kNone;
  return test::run(bare, a, scalar).totals.peak_top;
}

// ---- accuracy against data/reference ----

TEST(Split, EveryLawMatchesItsReferenceAt1kHz) {
  // Measured at the default 64 steps: peak within 1.4e-7, x_r within 1.1e-7;
  // the contact count of Kuwabara and Hertz equal to the reference's, Tsuji's
  // (whose late, slow contacts are the most chaotic) off by up to 4 (21
  // against 25; the adaptive scheme at contact_rtol 1e-6 keeps all 25, the
  // bounded scheme's default budget 24).
  struct Case {
    ContactLaw law;
    const char* ref;
    int contacts_off;
    bool dissipative;
  };
  const std::vector<double> a = test::elcentro(1000.0);
  for (const Case c : {Case{ContactLaw::kKuwabara, "elcentro_vines", 0, true},
                       Case{ContactLaw::kHertz, "elcentro_vines_hertz", 0, false},
                       Case{ContactLaw::kTsuji, "elcentro_vines_tsuji", 4, true}}) {
    const nlohmann::json ref = reference(c.ref);
    const SceneParams p = split_scene(c.law);
    const host::RunTotals t = test::run(p, a).totals;
    const double dpeak = rel(t.peak_top, ref["peak_top_displacement_m"].get<double>());
    const double b = bare_peak(p, a), xr = (b - t.peak_top) / b;
    std::printf("[ measured ] %s: peak rel error %.2e, x_r %.7f (reference %.7f), %lld contacts (%d), residual "
                "%.2e, most Runge-Kutta steps in a step %lld\n",
                c.ref, dpeak, xr, ref["x_r"].get<double>(), static_cast<long long>(t.count.contacts),
                ref["contacts"].get<int>(), t.ledger.relative_residual(),
                static_cast<long long>(t.count.max_substeps_in_step));
    SCOPED_TRACE(c.ref);
    EXPECT_LT(dpeak, 1e-6);
    EXPECT_LT(std::fabs(xr - ref["x_r"].get<double>()), 1e-6);
    EXPECT_LE(std::abs(t.count.contacts - ref["contacts"].get<int>()), c.contacts_off);
    EXPECT_LT(t.ledger.relative_residual(), 1e-5);  // measured 0.9-3.1e-6
    if (c.dissipative) EXPECT_GT(t.ledger.contact, 0.0);
    else EXPECT_NEAR(t.ledger.contact, 0.0, 1e-6 * t.ledger.input);  // Hertz is elastic
    EXPECT_EQ(t.count.cap_hits, 0);
    EXPECT_EQ(t.count.divergences, 0);
  }
}

TEST(Split, ConvergesWithItsSteps) {
  // Classic Runge-Kutta in w: Hertz's peak error falls from 3.2e-6 at 32
  // steps to 7.4e-9 at 128 (measured), and Tsuji's contacts all come back.
  const std::vector<double> a = test::elcentro(1000.0);
  const double truth = reference("elcentro_vines_hertz")["peak_top_displacement_m"].get<double>();
  const double e32 = rel(test::run(split_scene(ContactLaw::kHertz, 1000.0, 32), a).totals.peak_top, truth);
  const double e128 = rel(test::run(split_scene(ContactLaw::kHertz, 1000.0, 128), a).totals.peak_top, truth);
  std::printf("[ measured ] Hertz peak rel error: 32 steps %.2e, 128 steps %.2e\n", e32, e128);
  EXPECT_LT(e128 * 30, e32);
  EXPECT_LT(e128, 1e-7);
  const nlohmann::json tsuji = reference("elcentro_vines_tsuji");
  const host::RunTotals t = test::run(split_scene(ContactLaw::kTsuji, 1000.0, 128), a).totals;
  EXPECT_EQ(t.count.contacts, tsuji["contacts"].get<int>());
  EXPECT_LT(rel(t.elastic_energy, tsuji["elastic_energy_Js"].get<double>()), 1e-4);  // measured 5.9e-6
}

TEST(Split, FloatStaysCloseToTheReference) {
  // In float the split scheme is closer to the reference than the adaptive
  // one (measured: peak 6.1e-7 against 4.3e-5, x_r 1.0e-6 against 2.9e-5):
  // the contact is one scaled scalar equation, not the whole state.
  const nlohmann::json ref = reference("elcentro_vines");
  const std::vector<double> a = test::elcentro(1000.0);
  const SceneParams p = split_scene();
  const host::RunTotals t = test::run(p, a, host::Scalar::kFloat).totals;
  const double b = bare_peak(p, a, host::Scalar::kFloat), xr = (b - t.peak_top) / b;
  std::printf("[ measured ] float: peak rel error %.2e, x_r %.7f (%.7f), %lld contacts\n",
              rel(t.peak_top, ref["peak_top_displacement_m"].get<double>()), xr, ref["x_r"].get<double>(),
              static_cast<long long>(t.count.contacts));
  EXPECT_LT(rel(t.peak_top, ref["peak_top_displacement_m"].get<double>()), 1e-5);
  EXPECT_LT(std::fabs(xr - ref["x_r"].get<double>()), 1e-5);
  EXPECT_EQ(t.count.divergences, 0);
  EXPECT_LT(t.ledger.relative_residual(), 1e-4);
}

TEST(Split, At50HzAWholeContactFitsInAStep) {
  // At the record's own rate (the IC grid's) a contact of ~10 ms lies inside
  // a 20 ms step: the overlap's equation follows it whole, the frame takes
  // it through six moments (measured: peak 3.2e-6, 18 contacts as the
  // reference).
  const nlohmann::json ref = reference("elcentro_vines");
  const host::RunTotals t = test::run(split_scene(ContactLaw::kKuwabara, 50.0), test::elcentro(50.0)).totals;
  EXPECT_LT(rel(t.peak_top, ref["peak_top_displacement_m"].get<double>()), 1e-4);
  EXPECT_EQ(t.count.contacts, ref["contacts"].get<int>());
  EXPECT_EQ(t.count.divergences, 0);
}

TEST(Split, InitialConditionEnsembleAgreesWithTheAdaptiveScheme) {
  // The IC study's 33 x 33 grid (initial position over the free travel,
  // velocity over +-vmax, 50 Hz: data/studies/initial_conditions.toml,
  // ic_vines): mean and spread of x_r and E_r from the split scheme against
  // the adaptive one at contact_rtol 1e-10. A chaotic response: single runs
  // part late in the record (on a 7 x 7 subgrid the means of E_r differed
  // by 0.14 points), the statistics of the whole grid must not.
  const std::vector<double> a = test::elcentro(50.0);
  SceneParams base = split_scene(ContactLaw::kKuwabara, 50.0);
  base.loop.energy_ledger = false;
  base.loop.floor_peaks = false;
  SceneParams bare = base;
  bare.device.kind = DeviceKind::kNone;
  const host::RunTotals b = test::run(bare, a).totals;
  const double gap = design_vines(base.device.vines, 0.05 * 1115888.2994, 98000.0).gap;  // only its gap is read
  struct Stats {
    double sx = 0, sxx = 0, se = 0, see = 0;
    void add(double x, double e) {
      sx += x;
      sxx += x * x;
      se += e;
      see += e * e;
    }
  } split, adaptive;
  int n = 0;
  for (int i = 0; i <= 32; ++i)
    for (int j = 0; j <= 32; ++j) {
      SceneParams p = base;
      p.device.vines.start_at_left_wall = false;
      p.device.vines.initial_position_m = (-1.0 + i / 16.0) * gap;
      p.device.vines.initial_velocity_mps = (-1.0 + j / 16.0) * b.peak_top_velocity;
      const host::RunTotals s = test::run(p, a).totals;
      p.loop.contact_scheme = ContactScheme::kAdaptive;
      p.loop.contact_rtol = 1e-10;
      const host::RunTotals r = test::run(p, a).totals;
      auto xr = [&](const host::RunTotals& t) { return (b.peak_top - t.peak_top) / b.peak_top; };
      auto er = [&](const host::RunTotals& t) { return (b.elastic_energy - t.elastic_energy) / b.elastic_energy; };
      split.add(xr(s), er(s));
      adaptive.add(xr(r), er(r));
      EXPECT_EQ(s.count.divergences, 0);
      ++n;
    }
  auto mean = [n](double s) { return s / n; };
  auto sd = [n](double s, double ss) { return std::sqrt(std::max(ss / n - (s / n) * (s / n), 0.0)); };
  std::printf("[ measured ] %d runs: x_r %.5f +- %.5f (adaptive %.5f +- %.5f), E_r %.5f +- %.5f (%.5f +- %.5f)\n", n,
              mean(split.sx), sd(split.sx, split.sxx), mean(adaptive.sx), sd(adaptive.sx, adaptive.sxx),
              mean(split.se), sd(split.se, split.see), mean(adaptive.se), sd(adaptive.se, adaptive.see));
  EXPECT_NEAR(mean(split.sx), mean(adaptive.sx), 1e-3);  // 0.1 point
  EXPECT_NEAR(mean(split.se), mean(adaptive.se), 1e-3);
  EXPECT_NEAR(sd(split.sx, split.sxx), sd(adaptive.sx, adaptive.sxx), 1e-3);
  EXPECT_NEAR(sd(split.se, split.see), sd(adaptive.se, adaptive.see), 1e-3);
}

// ---- the work bound ----

TEST(Split, NoStepTakesMoreThanItsCap) {
  // On every step the Runge-Kutta steps taken (the counters' growth) stay
  // within kSplitCap loop.split_steps, and the loop's own maximum agrees; at
  // 1 kHz with the default steps the worst step takes ~40 (measured).
  for (const double rate : {1000.0, 50.0}) {
    const SceneParams p = split_scene(ContactLaw::kKuwabara, rate);
    const std::vector<double> a = test::elcentro(rate);
    auto eng = host::make_engine(p, host::Scalar::kDouble);
    ASSERT_NE(eng, nullptr);
    ASSERT_TRUE(eng->build(p).ok());
    eng->init(a[0]);
    long long worst = 0, before = 0;
    for (std::size_t k = 1; k < a.size(); ++k) {
      eng->step(a[k]);
      const long long now = eng->probe().count.substeps;
      worst = std::max(worst, now - before);
      before = now;
    }
    SCOPED_TRACE(rate);
    EXPECT_GT(worst, 0);
    EXPECT_LE(worst, kSplitCap * kSteps);
    EXPECT_EQ(eng->totals().count.max_substeps_in_step, worst);
  }
}

// ---- scene keys and link fields ----

TEST(SplitScene, KeysAreReadAndChecked) {
  const host::Scene s =
      host::parse_scene(scene_test::kBase + "[loop]\ncontact_scheme = \"split\"\nsplit_steps = 48\n", "ok.toml");
  EXPECT_EQ(s.params.loop.contact_scheme, ContactScheme::kSplit);
  EXPECT_EQ(s.params.loop.split_steps, 48);
  for (const char* bad : {"[loop]\nsplit_steps = 3\n", "[loop]\nsplit_steps = 1025\n"})
    scene_test::expect_refused(scene_test::kBase + bad, {"loop.split_steps", "[4, 1024]"});
  // An instantaneous impact has no contact to follow in time.
  scene_test::expect_refused(scene_test::kBase + "[vines]\nlaw = \"restitution\"\n[loop]\ncontact_scheme = \"split\"\n",
                             {"loop.contact_scheme", "finite contact duration"});
}

TEST(SplitLink, ConfigCarriesTheSchemeAndItsSteps) {
  link::NodeConfig c;
  c.scene = split_scene(ContactLaw::kKuwabara, 1000.0, 300);
  std::uint8_t blob[link::kMaxConfigBlob];
  const std::size_t n = link::encode(c, blob, sizeof blob);
  ASSERT_GT(n, 2u);
  link::NodeConfig d;
  ASSERT_TRUE(link::decode(blob, n, &d));
  EXPECT_EQ(d.scene.loop.contact_scheme, ContactScheme::kSplit);
  EXPECT_EQ(d.scene.loop.split_steps, 300);
  c.scene.loop.split_steps = kMaxSplitSteps + 1;  // out of range: encoded, refused on decode
  const std::size_t m = link::encode(c, blob, sizeof blob);
  EXPECT_FALSE(link::decode(blob, m, &d));
}

}  // namespace
