// The bounded contact scheme (loop.contact_scheme = "bounded",
// substep_bounded.hpp): accuracy against the converged reference
// (data/reference, DOP853 in long double), energy balance, the work bound on
// every step, float runs, other laws and rates, and the refusals of its
// scene keys and link fields.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>


#include "sim_host/scene/scene.hpp"
#include "reference_support.hpp"
#include "scene_support.hpp"
#include "support.hpp"
#include "vines/link/config.hpp"
#include "vines/step/substep_bounded.hpp"

namespace {

using namespace vines;

// The scene's default budget (what `contact_scheme = "bounded"` alone gets).
const int kBudget = LoopParams{}.bounded_substeps;

using test::reference;
using test::rel;

SceneParams bounded_scene(ContactLaw law = ContactLaw::kKuwabara, double rate_hz = 1000.0, int budget = kBudget) {
  SceneParams p = test::paper_scene(DeviceKind::kVines, law, rate_hz);
  p.loop.contact_scheme = ContactScheme::kBounded;
  p.loop.bounded_substeps = budget;
  return p;
}

// A run step by step with the loop's counters read after every step: the
// most sub-steps and events any single step took, from the counters' growth.
struct Watched {
  host::RunTotals totals;
  long long worst_step_substeps = 0, worst_step_events = 0, careful_steps = 0;
};

Watched watch(const SceneParams& p, const std::vector<double>& a, host::Scalar scalar = host::Scalar::kDouble) {
  Watched w;
  auto eng = host::make_engine(p, scalar);
  EXPECT_NE(eng, nullptr);
  if (!eng) return w;
  EXPECT_TRUE(eng->build(p).ok());
  eng->init(a[0]);
  Counters before = eng->probe().count;
  for (std::size_t k = 1; k < a.size(); ++k) {
    eng->step(a[k]);
    const Counters now = eng->probe().count;
    w.worst_step_substeps = std::max<long long>(w.worst_step_substeps, now.substeps - before.substeps);
    w.worst_step_events = std::max<long long>(w.worst_step_events, now.events - before.events);
    before = now;
  }
  w.totals = eng->totals();
  w.careful_steps = w.totals.count.careful_steps;
  return w;
}

// x_r of a run against the bare frame on the same samples.
double x_r(const SceneParams& p, const host::RunTotals& t, const std::vector<double>& a,
           host::Scalar scalar = host::Scalar::kDouble) {
  SceneParams bare = p;
  bare.device.kind = DeviceKind::kNone;
  const double b = test::run(bare, a, scalar).totals.peak_top;
  return (b - t.peak_top) / b;
}

// ---- accuracy: El Centro, Kuwabara, 1 kHz, against data/reference ----

TEST(Bounded, ElCentroMatchesTheReferenceAt1kHz) {
  const nlohmann::json ref = reference("elcentro_vines");
  const std::vector<double> a = test::elcentro(1000.0);
  const SceneParams p = bounded_scene();
  const Watched w = watch(p, a);
  const double xr = x_r(p, w.totals, a);
  const double dpeak = rel(w.totals.peak_top, ref["peak_top_displacement_m"].get<double>());
  std::printf("[ measured ] budget %d: peak rel error %.2e, %lld contacts, x_r %.5f (reference %.5f), energy "
              "residual %.2e\n",
              kBudget, dpeak, static_cast<long long>(w.totals.count.contacts), xr, ref["x_r"].get<double>(),
              w.totals.ledger.relative_residual());
  EXPECT_LT(dpeak, 1e-4);
  EXPECT_EQ(w.totals.count.contacts, ref["contacts"].get<int>());
  EXPECT_LT(std::fabs(xr - ref["x_r"].get<double>()), 1e-3);  // 0.1 point
  // Nothing was deferred or stepped over.
  EXPECT_EQ(w.totals.count.cap_hits, 0);
  EXPECT_EQ(w.totals.count.divergences, 0);
}

TEST(Bounded, ConvergesWithTheBudget) {
  // More sub-steps a step, closer to the reference: the error falls at least
  // 30-fold from 4 to 16 sub-steps (fifth-order steps: ~1000-fold).
  const double truth = reference("elcentro_vines")["peak_top_displacement_m"].get<double>();
  const std::vector<double> a = test::elcentro(1000.0);
  const double e4 = rel(test::run(bounded_scene(ContactLaw::kKuwabara, 1000.0, 4), a).totals.peak_top, truth);
  const double e16 = rel(test::run(bounded_scene(ContactLaw::kKuwabara, 1000.0, 16), a).totals.peak_top, truth);
  std::printf("[ measured ] peak rel error: 4 sub-steps %.2e, 16 sub-steps %.2e\n", e4, e16);
  EXPECT_LT(e16 * 30, e4);
  EXPECT_LT(e16, 1e-7);
}

TEST(Bounded, EnergyBalances) {
  // The ledger (input = stored + frame damping + contact dissipation) closes
  // to the scheme's truncation error: below 1e-5 of the energy put in (the
  // adaptive scheme at contact_rtol 1e-10: ~1e-11).
  const Watched w = watch(bounded_scene(), test::elcentro(1000.0));
  const Ledger& l = w.totals.ledger;
  EXPECT_LT(l.relative_residual(), 1e-5);
  EXPECT_GT(l.contact, 0.0);
}

// ---- the work bound ----

TEST(Bounded, NoStepTakesMoreThanItsBudget) {
  // On every step of the record the sub-steps taken (from the counters'
  // growth) stay within the budget, and the events within kBoundedEvents;
  // the loop's own maxima agree. Also for tiny budgets, where events must
  // wait (counted as cap hits), and at 50 Hz, where a whole contact falls in
  // one step.
  struct Case {
    double rate;
    int budget;
  };
  for (const Case c : {Case{1000.0, kBudget}, Case{1000.0, 2}, Case{1000.0, 3}, Case{50.0, 4}, Case{2048.0, 5}}) {
    const Watched w = watch(bounded_scene(ContactLaw::kKuwabara, c.rate, c.budget), test::elcentro(c.rate));
    SCOPED_TRACE(testing::Message() << c.rate << " Hz, budget " << c.budget);
    EXPECT_GT(w.careful_steps, 0);
    EXPECT_GT(w.worst_step_substeps, 0);
    EXPECT_LE(w.worst_step_substeps, c.budget);
    EXPECT_EQ(w.totals.count.max_substeps_in_step, w.worst_step_substeps);
    EXPECT_LE(w.worst_step_events, kBoundedEvents);
    EXPECT_LE(w.totals.count.max_events_in_step, kBoundedEvents);
    EXPECT_EQ(w.totals.count.rejected, 0);
    EXPECT_TRUE(std::isfinite(w.totals.peak_top));
    EXPECT_LT(w.totals.ledger.relative_residual(), 1e-2);
  }
}

TEST(Bounded, BudgetTooSmallIsReportedNotSilent) {
  // Two sub-steps cannot both start a contact and follow it through the
  // step: the contact start waits for the next step, counted.
  const Watched w = watch(bounded_scene(ContactLaw::kKuwabara, 1000.0, 2), test::elcentro(1000.0));
  EXPECT_GT(w.totals.count.cap_hits, 0);
  EXPECT_GT(w.totals.count.contacts, 10);
}

// ---- other laws, rates, float ----

TEST(Bounded, EveryContactLawMatchesItsReference) {
  // Peak within 1e-4 and the energy ledger closed; the contact count of the
  // chaotic laws within two of the reference's (the adaptive scheme's own
  // count moves with contact_rtol, see test_reference).
  struct Case {
    ContactLaw law;
    const char* ref;
  };
  const std::vector<double> a = test::elcentro(1000.0);
  for (const Case c : {Case{ContactLaw::kHertz, "elcentro_vines_hertz"}, Case{ContactLaw::kTsuji, "elcentro_vines_tsuji"},
                       Case{ContactLaw::kRestitution, "elcentro_vines_restitution"}}) {
    const nlohmann::json ref = reference(c.ref);
    const Watched w = watch(bounded_scene(c.law), a);
    const double dpeak = rel(w.totals.peak_top, ref["peak_top_displacement_m"].get<double>());
    std::printf("[ measured ] %s: peak rel error %.2e, %lld contacts (reference %d), residual %.2e\n", c.ref, dpeak,
                static_cast<long long>(w.totals.count.contacts), ref["contacts"].get<int>(),
                w.totals.ledger.relative_residual());
    SCOPED_TRACE(c.ref);
    EXPECT_LT(dpeak, 1e-4);
    EXPECT_LE(std::abs(w.totals.count.contacts - ref["contacts"].get<int>()), 2);
    EXPECT_LT(w.totals.ledger.relative_residual(), 1e-5);
    EXPECT_LE(w.worst_step_substeps, kBudget);
    EXPECT_EQ(w.totals.count.divergences, 0);
  }
}

TEST(Bounded, At2048HzMatchesTheAdaptiveScheme) {
  // 2048 Hz puts the samples off the record's 50 Hz knots: a different
  // piecewise-linear input, so the truth here is the adaptive scheme at
  // contact_rtol 1e-12 on the same samples.
  const std::vector<double> a = test::elcentro(2048.0);
  SceneParams tight = test::paper_scene(DeviceKind::kVines, ContactLaw::kKuwabara, 2048.0);
  tight.loop.contact_rtol = 1e-12;
  const test::Outcome truth = test::run(tight, a);
  const Watched w = watch(bounded_scene(ContactLaw::kKuwabara, 2048.0), a);
  const double dpeak = rel(w.totals.peak_top, truth.totals.peak_top);
  std::printf("[ measured ] 2048 Hz: peak rel diff %.2e, %lld contacts (adaptive %lld)\n", dpeak,
              static_cast<long long>(w.totals.count.contacts), static_cast<long long>(truth.totals.count.contacts));
  EXPECT_LT(dpeak, 1e-4);
  EXPECT_EQ(w.totals.count.contacts, truth.totals.count.contacts);
  EXPECT_LE(w.worst_step_substeps, kBudget);
}

TEST(Bounded, FloatRunsFiniteAndClose) {
  // Float: the peak within 1e-4 of the reference (the adaptive scheme in
  // float: 2e-5), x_r within half a point; the contact count is chaotic in
  // float (rounding moves late impacts) and only bounded.
  const nlohmann::json ref = reference("elcentro_vines");
  const std::vector<double> a = test::elcentro(1000.0);
  const SceneParams p = bounded_scene();
  const Watched w = watch(p, a, host::Scalar::kFloat);
  const double dpeak = rel(w.totals.peak_top, ref["peak_top_displacement_m"].get<double>());
  const double xr = x_r(p, w.totals, a, host::Scalar::kFloat);
  std::printf("[ measured ] float: peak rel error %.2e, %lld contacts, x_r %.5f, residual %.2e\n", dpeak,
              static_cast<long long>(w.totals.count.contacts), xr, w.totals.ledger.relative_residual());
  EXPECT_TRUE(std::isfinite(w.totals.peak_top) && std::isfinite(w.totals.elastic_energy));
  EXPECT_LT(dpeak, 1e-4);
  EXPECT_LT(std::fabs(xr - ref["x_r"].get<double>()), 5e-3);
  EXPECT_GE(w.totals.count.contacts, 12);
  EXPECT_LE(w.totals.count.contacts, 30);
  EXPECT_LT(w.totals.ledger.relative_residual(), 1e-4);
  EXPECT_LE(w.worst_step_substeps, kBudget);
  EXPECT_EQ(w.totals.count.divergences, 0);
}

TEST(Bounded, DefaultSchemeIsAdaptive) {
  // Scenes without the key keep the adaptive scheme (and its results).
  EXPECT_EQ(LoopParams{}.contact_scheme, ContactScheme::kAdaptive);
  const std::vector<double> a = test::elcentro(1000.0);
  const SceneParams p = test::paper_scene(DeviceKind::kVines);
  const test::Outcome o = test::run(p, a);
  EXPECT_GT(o.totals.count.max_substeps_in_step, kBudget);  // the adaptive scheme's own count
  EXPECT_EQ(o.totals.count.max_events_in_step, 0);          // kept by the bounded scheme only
}

// ---- scene keys and link fields ----

// The scene tests' valid VI NES scene with these [loop] keys.
std::string with_loop(const std::string& loop_keys) { return scene_test::kBase + "[loop]\n" + loop_keys; }

std::string error_of(const std::string& loop_keys) { return scene_test::error_of(with_loop(loop_keys)); }

TEST(BoundedScene, KeysAreReadAndChecked) {
  const host::Scene s = host::parse_scene(with_loop("contact_scheme = \"bounded\"\nbounded_substeps = 12\n"), "ok.toml");
  EXPECT_EQ(s.params.loop.contact_scheme, ContactScheme::kBounded);
  EXPECT_EQ(s.params.loop.bounded_substeps, 12);
  EXPECT_EQ(host::parse_scene(with_loop(""), "ok.toml").params.loop.contact_scheme, ContactScheme::kAdaptive);
  struct Bad {
    const char* keys;
    const char* key;
    const char* what;
  };
  for (const Bad b : {Bad{"contact_scheme = \"fast\"\n", "loop.contact_scheme", "\"adaptive\", \"bounded\""},
                      Bad{"contact_scheme = 1\n", "loop.contact_scheme", "must be a string"},
                      Bad{"bounded_substeps = 1\n", "loop.bounded_substeps", "[2, 64]"},
                      Bad{"bounded_substeps = 65\n", "loop.bounded_substeps", "[2, 64]"},
                      Bad{"bounded_substeps = 8.0\n", "loop.bounded_substeps", "integer"},
                      Bad{"bounded_substep = 8\n", "loop.bounded_substep", "unknown key"}}) {
    const std::string msg = error_of(b.keys);
    SCOPED_TRACE(b.keys);
    ASSERT_FALSE(msg.empty());
    EXPECT_NE(msg.find("bad.toml:"), std::string::npos) << msg;
    EXPECT_NE(msg.find(b.key), std::string::npos) << msg;
    EXPECT_NE(msg.find(b.what), std::string::npos) << msg;
  }
  // The budget is checked whatever the scheme (a scene flips by one word).
  EXPECT_NE(error_of("contact_scheme = \"adaptive\"\nbounded_substeps = 0\n").find("loop.bounded_substeps"),
            std::string::npos);
}

TEST(BoundedScene, ValidateRefusesOutOfRangeValues) {
  SceneParams p = bounded_scene();
  EXPECT_TRUE(validate(p).ok());
  p.loop.bounded_substeps = kMaxBoundedSubsteps + 1;
  EXPECT_STREQ(validate(p).field, "loop.bounded_substeps");
  p = bounded_scene();
  p.loop.contact_scheme = static_cast<ContactScheme>(3);
  EXPECT_STREQ(validate(p).field, "loop.contact_scheme");
}

TEST(BoundedLink, ConfigCarriesTheSchemeAndRefusesBadValues) {
  link::NodeConfig c;
  c.scene = bounded_scene(ContactLaw::kKuwabara, 1000.0, 11);
  std::uint8_t blob[link::kMaxConfigBlob];
  const std::size_t n = link::encode(c, blob, sizeof blob);
  ASSERT_GT(n, 2u);
  link::NodeConfig d;
  ASSERT_TRUE(link::decode(blob, n, &d));
  EXPECT_EQ(d.scene.loop.contact_scheme, ContactScheme::kBounded);
  EXPECT_EQ(d.scene.loop.bounded_substeps, 11);
  // The scheme and budget bytes and the split scheme's steps (u16), before
  // the deadline budget (u32), the hybrid compensator's kind (u8) and window
  // (f64) and the twin's estimator (u8), the last fields.
  constexpr std::size_t kTail = 4 + 1 + 8 + 1;
  const std::size_t at_scheme = n - kTail - 4, at_budget = n - kTail - 3;
  EXPECT_EQ(blob[at_scheme], 1);
  EXPECT_EQ(blob[at_budget], 11);
  for (const auto& [at, value] :
       {std::pair<std::size_t, std::uint8_t>{at_scheme, 3}, {at_budget, 1}, {at_budget, 65}}) {
    std::uint8_t bad[link::kMaxConfigBlob];
    std::memcpy(bad, blob, n);
    bad[at] = value;
    EXPECT_FALSE(link::decode(bad, n, &d)) << at << " " << int(value);
  }
  // A blob of the previous layout (without the two bytes) is refused.
  std::uint8_t old[link::kMaxConfigBlob];
  std::memcpy(old, blob, at_scheme);
  std::memcpy(old + at_scheme, blob + at_scheme + 4, kTail);
  EXPECT_FALSE(link::decode(old, n - 4, &d));
}

}  // namespace
