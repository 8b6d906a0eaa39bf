// The loop's state on the host Engine (sim_host/engines/engine.hpp): state()
// and load_state() continue a run bit for bit on another engine of the same
// model (double, float and fixed point; bare frame, TMD, VI NES) and refuse
// what is not such a state. set_physical(): test_set_physical.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sim_host/engines/build_engine.hpp"
#include "sim_host/scene/names.hpp"
#include "sim_host/scene/scene.hpp"
#include "engine_support.hpp"
#include "support.hpp"

namespace {

using namespace vines;
using namespace vines::host;

using test::built;
using test::has;
using test::kScenes;
using test::samples;

// Every figure of the totals and the snapshot, equal (bit for bit but for
// the sign of zero).
void expect_same(const RunTotals& a, const RunTotals& b, const Snapshot& s, const Snapshot& t, const std::string& what) {
  for (int i = 0; i < kMaxStories; ++i) {
    EXPECT_EQ(a.peak_x[i], b.peak_x[i]) << what;
    EXPECT_EQ(a.peak_drift[i], b.peak_drift[i]) << what;
    EXPECT_EQ(s.x[i], t.x[i]) << what;
    EXPECT_EQ(s.v[i], t.v[i]) << what;
    EXPECT_EQ(s.acc[i], t.acc[i]) << what;
  }
  using Pairs = std::initializer_list<std::pair<double, double>>;
  for (auto [u, w] : Pairs{{a.peak_top, b.peak_top}, {a.t_peak_top, b.t_peak_top},
                      {a.peak_top_velocity, b.peak_top_velocity}, {a.elastic_energy, b.elastic_energy},
                      {a.strain_increments, b.strain_increments}, {a.max_overlap, b.max_overlap},
                      {a.ledger.initial, b.ledger.initial}, {a.ledger.input, b.ledger.input},
                      {a.ledger.damping, b.ledger.damping}, {a.ledger.contact, b.ledger.contact},
                      {a.ledger.residual, b.ledger.residual}, {a.ledger.max_abs_residual, b.ledger.max_abs_residual},
                      {s.t, t.t}, {s.ag, t.ag}, {s.elastic_energy, t.elastic_energy}, {s.particle_x, t.particle_x},
                      {s.particle_v, t.particle_v}, {s.contact_force, t.contact_force}, {s.tmd_x, t.tmd_x},
                      {s.tmd_v, t.tmd_v}})
    EXPECT_EQ(u, w) << what;
  EXPECT_EQ(s.mode, t.mode) << what;
  EXPECT_EQ(a.count.steps, b.count.steps) << what;
  EXPECT_EQ(a.count.contacts, b.count.contacts) << what;
  EXPECT_EQ(a.count.events, b.count.events) << what;
  EXPECT_EQ(a.count.substeps, b.count.substeps) << what;
  EXPECT_EQ(a.count.bad_samples, b.count.bad_samples) << what;
  EXPECT_EQ(a.fixed_saturations, b.fixed_saturations) << what;
}

// Half a record, saved; the rest on the engine and, from the state, on a
// second engine of the same parameters (never initialised): the same bits.
void save_and_continue(const SceneParams& p, Scalar scalar, const std::string& what) {
  const std::vector<double> a = samples();
  const std::size_t half = 3217;  // inside the strong motion
  const auto one = built(p, scalar), two = built(p, scalar);
  one->init(a[0]);
  one->run(a.data() + 1, half - 1);
  const std::vector<std::uint8_t> st = one->state();
  one->run(a.data() + half, a.size() - half);
  ASSERT_EQ(two->load_state(st.data(), st.size()), "") << what;
  EXPECT_EQ(two->state(), st) << what;
  two->run(a.data() + half, a.size() - half);
  expect_same(one->totals(), two->totals(), one->snapshot(), two->snapshot(), what);
  EXPECT_EQ(one->state(), two->state()) << what;
  EXPECT_GT(one->totals().peak_top, 1e-3) << what;  // the building moved
  if (p.device.kind == DeviceKind::kVines) EXPECT_GT(one->totals().count.contacts, 0) << what;
  std::printf("%s: state %zu bytes, the same bits after %zu steps more\n", what.c_str(), st.size(),
              a.size() - half);
}

TEST(LoopState, SaveAndLoadContinueBitForBit) {
  for (Scalar scalar : {Scalar::kDouble, Scalar::kFloat}) {
    for (DeviceKind kind : {DeviceKind::kNone, DeviceKind::kTmd, DeviceKind::kVines}) {
      const std::string what = std::string(scalar_name(scalar)) + " " + device_name(kind);
      save_and_continue(test::paper_scene(kind), scalar, what);
    }
    save_and_continue(test::paper_scene(DeviceKind::kVines, ContactLaw::kRestitution), scalar,
                      std::string(scalar_name(scalar)) + " vines restitution");
    SceneParams bounded = test::paper_scene(DeviceKind::kVines);
    bounded.loop.contact_scheme = ContactScheme::kBounded;
    save_and_continue(bounded, scalar, std::string(scalar_name(scalar)) + " vines bounded");
  }
  // Fixed point: the shipped scenes.
  for (const char* device : {"bare", "tmd", "vines"}) {
    const Scene sc = load_scene(kScenes + "elcentro_" + std::string(device) + "_fixed.toml");
    save_and_continue(sc.params, Scalar::kFixed, std::string("fixed ") + device);
  }
}

// What is not a state of this engine's model is refused, and nothing changes.
TEST(LoopState, RefusesOtherStates) {
  const std::vector<double> a = samples();
  const SceneParams p = test::paper_scene(DeviceKind::kVines);
  const auto eng = built(p, Scalar::kDouble);
  eng->init(a[0]);
  eng->run(a.data() + 1, 2000);
  const std::vector<std::uint8_t> own = eng->state();

  SceneParams damaged = p;
  damaged.frame.stiffness_scale = 0.9;
  const auto other_model = built(damaged, Scalar::kDouble);
  other_model->init(0);
  const auto tmd = built(test::paper_scene(DeviceKind::kTmd), Scalar::kDouble);
  tmd->init(0);
  const auto in_float = built(p, Scalar::kFloat);
  in_float->init(0);
  SceneParams elsewhere = p;  // another start of the particle: another model too
  elsewhere.device.vines.start_at_left_wall = false;
  elsewhere.device.vines.initial_position_m = 0.01;
  const auto other_start = built(elsewhere, Scalar::kDouble);
  other_start->init(0);

  std::vector<std::uint8_t> cut = own;
  cut.resize(own.size() - 1);
  std::vector<std::uint8_t> header_only = own;
  header_only.resize(20);
  std::vector<std::uint8_t> longer = own;
  longer.push_back(0);
  std::vector<std::uint8_t> junk = own;
  junk[0] ^= 0xff;
  std::vector<std::uint8_t> newer = own;
  newer[8] += 1;  // the version
  const struct {
    std::vector<std::uint8_t> bytes;
    const char* part;
  } refused[] = {{other_model->state(), "a state of another model"},
                 {other_start->state(), "a state of another model"},
                 {tmd->state(), "a state of another engine (10 stories, double, tmd; this one: 10 stories, "
                                "double, vines (kuwabara))"},
                 {in_float->state(), "a state of another engine (10 stories, float"},
                 {cut, "truncated"},
                 {header_only, "truncated"},
                 {longer, "past its end"},
                 {junk, "not a vines loop state"},
                 {newer, "version 2"},
                 {{}, "not a vines loop state"}};
  for (const auto& r : refused) {
    const std::string why = eng->load_state(r.bytes.data(), r.bytes.size());
    EXPECT_TRUE(has(why, r.part)) << why << "\nlacks: " << r.part;
    std::printf("refused: %s\n", why.c_str());
    EXPECT_EQ(eng->state(), own) << r.part;
  }
  EXPECT_EQ(eng->load_state(own.data(), own.size()), "");
}

// The model's fingerprint is cached (loop_state::Fingerprint) but follows
// the model: new initial conditions, a rebuild or a loaded image make the
// states saved before them another model's, and back again.
TEST(LoopState, TheFingerprintFollowsTheModel) {
  const SceneParams p = test::paper_scene(DeviceKind::kVines);
  SceneParams elsewhere = p;
  elsewhere.device.vines.start_at_left_wall = false;
  elsewhere.device.vines.initial_position_m = 0.01;
  for (Scalar scalar : {Scalar::kDouble, Scalar::kFixed}) {
    SceneParams q = p, r = elsewhere;
    if (scalar == Scalar::kFixed) q.loop.contact_scheme = r.loop.contact_scheme = ContactScheme::kSplit;
    const auto eng = built(q, scalar);
    eng->init(0);
    const std::vector<std::uint8_t> before = eng->state(), image = eng->model_image();
    ASSERT_TRUE(eng->set_initial_conditions(r).ok());
    EXPECT_TRUE(has(eng->load_state(before.data(), before.size()), "another model")) << scalar_name(scalar);
    ASSERT_TRUE(eng->build(q).ok());
    EXPECT_EQ(eng->load_state(before.data(), before.size()), "") << scalar_name(scalar);
    ASSERT_TRUE(eng->set_initial_conditions(r).ok());
    ASSERT_EQ(eng->load_image(image.data(), image.size()), "");
    EXPECT_EQ(eng->load_state(before.data(), before.size()), "") << scalar_name(scalar);
  }
}

}  // namespace
