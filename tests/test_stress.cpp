// The stability stress (`vines stress`): thousands of random scenes over the
// whole parameter space pass every check; the checks catch a broken run; the
// draw does not depend on threads; a too-small sub-step cap is reported;
// scenes that cannot be run (negative damping, contact scales no run can
// keep) are refused with their reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/engines/engine.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/limits.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/studies/stress.hpp"
#include "support.hpp"

namespace {

using namespace vines;
using namespace vines::host;

const std::vector<StressRecord>& records() {
  static const std::vector<StressRecord> r = load_stress_records();
  return r;
}

StressRun stress(std::uint64_t seed, std::int64_t count, int threads) {
  StressOptions opt;
  opt.seed = seed;
  opt.count = count;
  opt.threads = threads;
  opt.progress = false;
  return run_stress(opt, records(), nullptr);
}

// ---- the stress itself ----

TEST(Stress, TwoThousandRandomScenesPassEveryCheck) {
  const StressRun run = stress(7, 2000, 0);
  std::set<int> stories, recs;
  std::map<std::string, int> devices;
  int refused = 0, floats = 0, with_contacts = 0, small_caps = 0, small_cap_hits = 0;
  for (std::size_t i = 0; i < run.results.size(); ++i) {
    const StressCase& c = run.cases[i];
    const StressResult& r = run.results[i];
    if (!r.refusal.empty()) {
      ++refused;
      continue;
    }
    EXPECT_TRUE(r.ok()) << case_report(c, r, records()).dump(1);
    for (int k : {kFinite, kEnergy, kGuards, kConvergence}) EXPECT_TRUE(r.checks[k].applies) << i;
    stories.insert(c.params.frame.stories);
    recs.insert(c.record);
    const bool vines = c.params.device.kind == DeviceKind::kVines;
    ++devices[vines ? std::to_string(static_cast<int>(c.params.device.vines.law)) : "none"];
    floats += c.scalar == Scalar::kFloat;
    with_contacts += r.contacts > 0;
    if (r.checks[kSmallCap].applies) {
      ++small_caps;
      small_cap_hits += r.detail["small_cap"]["cap_hits"].get<long long>() > 0;
    }
  }
  // Refusals are the exception, and the draw covers the whole space.
  EXPECT_LT(refused, 100);
  std::vector<int> all = compiled_frames(Scalar::kDouble, DeviceKind::kVines);
  EXPECT_EQ(stories, std::set<int>(all.begin(), all.end()));
  EXPECT_EQ(recs.size(), records().size());
  EXPECT_EQ(devices.size(), 5u);  // the bare frame and the four laws
  for (const auto& [device, n] : devices) EXPECT_GT(n, 250) << device;
  EXPECT_GT(floats, 100);
  EXPECT_GT(with_contacts, 800);
  // The tiny caps did bite, and were reported.
  EXPECT_GT(small_caps, 100);
  EXPECT_GT(small_cap_hits, small_caps / 2);
}

TEST(Stress, RestitutionImpactsNeverLeaveTheParticleBeyondAWall) {
  // Two cases of `vines stress --seed 1` (168, 175) written as scenes: 15x and
  // 0.8x PGA, 10 and 20 stories, 141 and 51 Hz. Impacts placed past the wall
  // once left the particle there (cm deep at 15x PGA).
  for (const char* name : {"case_168", "case_175"}) {
    SCOPED_TRACE(name);
    const Scene s = load_scene(std::string(VINES_TEST_DATA_DIR) + "/restitution_tunnelling/" + name + ".toml");
    const Excitation ex = load_excitation(s, "");
    auto eng = make_engine(s.params, s.scalar);
    // The cases' frames are in the release build (VINES_STRESS_STORY_COUNTS).
    ASSERT_NE(eng, nullptr) << missing_engine(s.params, s.scalar);
    ASSERT_TRUE(eng->build(s.params).ok());
    eng->init(ex.samples[0]);
    double deepest = 0;
    for (std::size_t k = 1; k < ex.samples.size(); ++k) {
      eng->step(ex.samples[k]);
      deepest = std::max(deepest, eng->probe().overlap);
    }
    EXPECT_LT(deepest, 1e-9);
  }
}

TEST(Stress, ResultsDoNotDependOnThreads) {
  const StressRun one = stress(11, 60, 1), two = stress(11, 60, 2);
  for (std::size_t i = 0; i < one.results.size(); ++i) {
    EXPECT_EQ(one.results[i].refusal, two.results[i].refusal) << i;
    EXPECT_EQ(one.results[i].steps, two.results[i].steps) << i;
    for (int k = 0; k < kCheckCount; ++k) EXPECT_EQ(one.results[i].checks[k].value, two.results[i].checks[k].value) << i;
  }
  // Case K is the same scene whoever draws it.
  const StressCase again = draw_case(11, 42, records(), StressLimits{});
  EXPECT_EQ(case_json(again, records()), case_json(two.cases[42], records()));
}

// A VI NES case of the draw with contacts in its window.
StressCase case_with_contacts(ContactLaw law) {
  for (std::int64_t k = 0; k < 500; ++k) {
    StressCase c = draw_case(5, k, records(), StressLimits{});
    if (c.params.device.kind != DeviceKind::kVines || c.params.device.vines.law != law || c.scalar != Scalar::kDouble)
      continue;
    const StressResult r = run_case(c, records());
    if (r.refusal.empty() && r.contacts >= 3) return c;
  }
  throw std::runtime_error("no case with contacts");
}

TEST(Stress, ChecksCatchABrokenRun) {
  // With one sub-step per sensor step the contacts are not resolved: the
  // checks must say so (cap hits, and the overlap, energy or half-step
  // checks). A case whose contact is shorter than 16 of those sub-steps is
  // refused before it runs (docs/model.md 7.8); then the smallest cap that
  // loads it is taken, whose cap hits the checks must still report.
  for (ContactLaw law : {ContactLaw::kHertz, ContactLaw::kKuwabara}) {
    StressCase c = case_with_contacts(law);
    ASSERT_TRUE(run_case(c, records()).ok());
    c.params.loop.max_substeps_per_step = 1;
    const bool refused = check_contact_scales(c.params).has_value();
    if (refused) {
      const StressResult r = run_case(c, records());
      EXPECT_NE(r.refusal.find("Hertz contact time under 16 smallest sub-steps"), std::string::npos) << r.refusal;
      while (check_contact_scales(c.params)) ++c.params.loop.max_substeps_per_step;
    }
    const StressResult r = run_case(c, records());
    ASSERT_TRUE(r.refusal.empty()) << r.refusal;
    EXPECT_FALSE(r.ok()) << "cap " << c.params.loop.max_substeps_per_step;
    EXPECT_FALSE(r.checks[kCap].ok());
    if (!refused)
      EXPECT_FALSE(r.checks[kOverlap].ok() && r.checks[kEnergy].ok() && r.checks[kConvergence].ok())
          << case_report(c, r, records()).dump(1);
  }
}

TEST(Stress, ACaseIsWrittenAsASceneThatRunsTheSame) {
  const StressCase c = case_with_contacts(ContactLaw::kTsuji);
  const std::string dir = ::testing::TempDir() + "vines_stress_case";
  const Scene scene = load_scene(write_case_scene(c, records(), dir));
  RunOptions opt;
  opt.quiet = true;
  const RunReport r = run_scene(scene, opt);
  // Same engine, same samples: the same run as the stress made.
  auto eng = make_engine(c.params, c.scalar);
  ASSERT_TRUE(eng->build(c.params).ok());
  const std::vector<double> a = case_samples(c, records());
  eng->init(a[0]);
  for (std::size_t k = 1; k < a.size(); ++k) eng->step(a[k]);
  EXPECT_EQ(r.totals.peak_top, eng->totals().peak_top);
  EXPECT_EQ(r.totals.count.contacts, eng->totals().count.contacts);
}

// Engine::run (the firmware's run(): blocks of exact steps) and step() give
// the same run bit for bit: with the outputs a study reads (run's block path)
// and with the energy ledger and per-floor peaks (step by step), through a
// non-finite sample.
TEST(Stress, EngineRunIsTheStepLoop) {
  StressCase c = case_with_contacts(ContactLaw::kKuwabara);
  std::vector<double> a = case_samples(c, records());
  a[a.size() / 3] = std::numeric_limits<double>::quiet_NaN();
  for (const bool outputs : {false, true}) {
    c.params.loop.energy_ledger = outputs;
    c.params.loop.floor_peaks = outputs;
    auto stepped = make_engine(c.params, c.scalar), whole = make_engine(c.params, c.scalar);
    ASSERT_TRUE(stepped->build(c.params).ok());
    ASSERT_TRUE(whole->build(c.params).ok());
    stepped->init(a[0]);
    for (std::size_t k = 1; k < a.size(); ++k) stepped->step(a[k]);
    whole->init(a[0]);
    whole->run(a.data() + 1, a.size() - 1);
    const RunTotals s = stepped->totals(), w = whole->totals();
    EXPECT_GT(w.count.contacts, 0);
    EXPECT_EQ(w.count.steps, static_cast<std::int64_t>(a.size() - 1));
    EXPECT_EQ(w.count.bad_samples, 1);
    EXPECT_EQ(w.peak_top, s.peak_top);
    EXPECT_EQ(w.t_peak_top, s.t_peak_top);
    EXPECT_EQ(w.peak_top_velocity, s.peak_top_velocity);
    EXPECT_EQ(w.elastic_energy, s.elastic_energy);
    EXPECT_EQ(w.max_overlap, s.max_overlap);
    EXPECT_EQ(w.count.careful_steps, s.count.careful_steps);
    EXPECT_EQ(w.count.substeps, s.count.substeps);
    EXPECT_EQ(w.count.contacts, s.count.contacts);
    EXPECT_EQ(w.count.bad_samples, s.count.bad_samples);
    EXPECT_EQ(w.count.divergences, s.count.divergences);
    EXPECT_EQ(w.ledger.residual, s.ledger.residual);
  }
}

// ---- sub-step cap ----

// A uniform frame of n stories (100 t floors, f1 near 10/n Hz), a VI NES of
// 5 % on the top floor, El Centro at three times its PGA, 200 Hz.
SceneParams tall_vines(int n, ContactLaw law) {
  SceneParams p;
  p.frame.stories = n;
  for (int i = 0; i < n; ++i) {
    p.frame.mass_kg[i] = 1e5;
    p.frame.stiffness_n_per_m[i] = 4e9 / n;
  }
  p.device.kind = DeviceKind::kVines;
  p.device.vines.law = law;
  p.loop.sensor_rate_hz = 200.0;
  return p;
}

TEST(Stress, TooSmallSubstepCapIsReportedOnEveryStressFrame) {
  std::vector<double> a = test::elcentro(200.0);
  a.resize(2001);
  for (double& x : a) x *= 3.0;
  for (int n : compiled_frames(Scalar::kDouble, DeviceKind::kVines))
    for (int code = 0; code < kContactLawCount; ++code) {
      const ContactLaw law = static_cast<ContactLaw>(code);
      SCOPED_TRACE(n);
      SCOPED_TRACE(law_name(law));
      SceneParams p = tall_vines(n, law);
      const test::Outcome fine = test::run(p, a);
      EXPECT_GT(fine.totals.count.contacts, 0);
      EXPECT_EQ(fine.totals.count.cap_hits, 0);
      p.loop.max_substeps_per_step = 2;
      const test::Outcome capped = test::run(p, a);
      EXPECT_GT(capped.totals.count.cap_hits, 0);
      EXPECT_EQ(capped.totals.count.max_substeps_in_step, 2);
      EXPECT_TRUE(std::isfinite(capped.totals.peak_top));
      EXPECT_TRUE(std::isfinite(capped.last.particle_x));
    }
}

// ---- refusals ----

TEST(Stress, NegativeRayleighDampingIsRefused) {
  // 5 % on mode 1 and 0.5 % on mode 3: C = a0 M + a1 K with a1 < 0, so the
  // modes above 3 would be negatively damped.
  SceneParams p = test::paper_scene(DeviceKind::kVines);
  p.frame.damping = DampingRule::kRayleigh;
  p.frame.rayleigh_zeta[0] = 0.05;
  p.frame.rayleigh_zeta[1] = 0.005;
  p.frame.rayleigh_modes[1] = 3;
  for (DeviceKind kind : {DeviceKind::kNone, DeviceKind::kTmd, DeviceKind::kVines}) {
    p.device.kind = kind;
    const ParamError e = make_engine(p, Scalar::kDouble)->build(p);
    ASSERT_FALSE(e.ok());
    EXPECT_STREQ(e.field, "frame.rayleigh_zeta");
    EXPECT_NE(std::string(e.message).find("negative damping ratio"), std::string::npos) << e.message;
  }
  // The same pair the other way round is a fine frame.
  std::swap(p.frame.rayleigh_zeta[0], p.frame.rayleigh_zeta[1]);
  EXPECT_TRUE(make_engine(p, Scalar::kDouble)->build(p).ok());
}

TEST(Stress, NegativeRayleighDampingSceneFileIsRefusedBeforeRunning) {
  const Scene s = parse_scene(R"(
[frame]
damping = "rayleigh"
rayleigh_zeta = [0.05, 0.005]
rayleigh_modes = [1, 3]
[record]
path = "elcentro_1940_ns_2688pts_dt002_time_g.dat"
format = "time-accel"
duration_s = 1.0
)",
                              "damped.toml");
  try {
    run_scene(s, RunOptions{});
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("damped.toml: frame.rayleigh_zeta: gives another mode a negative damping"),
              std::string::npos)
        << e.what();
  }
}

// A drawn case with contact scales no run can keep is refused as its scene
// file would be (docs/model.md 7.8), with the rule as its reason.
TEST(Stress, ContactScalesNoRunCanKeepAreRefused) {
  StressCase c = case_with_contacts(ContactLaw::kKuwabara);
  c.params.device.mass_kg = 1e-9;
  EXPECT_EQ(run_case(c, records()).refusal, "device.mass_kg: Hertz contact time under 16 smallest sub-steps");
  c.params.device.mass_kg = 0.0;
  c.params.device.vines.young_pa = 1.0;
  EXPECT_EQ(run_case(c, records()).refusal, "vines.young_pa: Hertz overlap deeper than the radius");
}

TEST(Stress, FramesWithoutAnEngineAreRefusedTruthfully) {
  // Every frame the registry lists has its engines, and nothing else does.
  for (Scalar scalar : {Scalar::kDouble, Scalar::kFloat, Scalar::kFixed})
    for (DeviceKind kind : {DeviceKind::kNone, DeviceKind::kTmd, DeviceKind::kVines})
      for (int n = 1; n <= kMaxStories; ++n) {
        SceneParams p;
        p.frame.stories = n;
        p.device.kind = kind;
        const std::vector<int> listed = compiled_frames(scalar, kind);
        const bool has = std::find(listed.begin(), listed.end(), n) != listed.end();
        EXPECT_EQ(make_engine(p, scalar) != nullptr, has) << n << " " << scalar_name(scalar);
        const std::string why = kind == DeviceKind::kTmd && n > 30 ? "compiles only up to 30 stories"
                                                                    : "no compiled engine for " + std::to_string(n) + " stories";
        if (!has) {
          EXPECT_NE(missing_engine(p, scalar).find(why), std::string::npos) << missing_engine(p, scalar);
        }
      }
  // A stress-only frame (up to 30 stories) has no TMD and no float, and the
  // message says how to get them.
  const std::vector<int> all = compiled_frames(Scalar::kDouble, DeviceKind::kNone);
  const std::vector<int> tmd = compiled_frames(Scalar::kDouble, DeviceKind::kTmd);
  for (int n : all) {
    if (n > 30 || std::find(tmd.begin(), tmd.end(), n) != tmd.end()) continue;
    SceneParams p;
    p.frame.stories = n;
    p.device.kind = DeviceKind::kTmd;
    const std::string msg = missing_engine(p, Scalar::kDouble);
    EXPECT_NE(msg.find("with a TMD in double"), std::string::npos) << msg;
    EXPECT_NE(msg.find("(no device or a VI NES, double only)"), std::string::npos) << msg;
    EXPECT_NE(compiled_story_counts().find(std::to_string(n)), std::string::npos);
  }
}

}  // namespace
