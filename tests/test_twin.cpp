// The twin monitor with its estimator (docs/twin.md): the frame's state and
// each story's stiffness kept on the measured floors, against truths that
// are not the node's model (a lost story, a sphere started elsewhere, a
// detuned TMD, a stuck sphere); the estimator in float against double on the
// same image; bad inputs refused with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "sim_host/engines/build_engine.hpp"
#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/modes/twin.hpp"
#include "sim_host/run/run.hpp"
#include "vines/link/model_plant.hpp"
#include "vines/link/twin_plant.hpp"
#include "vines/twin/estimator.hpp"

namespace vines::host {
namespace {

std::string scene_path(const std::string& name) { return std::string(VINES_SOURCE_DIR) + "/data/scenes/" + name; }

HilOptions twin(double duration_s, const std::string& truth = "") {
  HilOptions o;
  o.node_command = VINES_EXE;
  o.mode = HilMode::kTwin;
  o.duration_s = duration_s;
  o.timeout_s = 20;
  o.sensors = {3, 6, 8, 10};
  o.measure_noise_pct = 5;
  o.truth_path = truth.empty() ? "" : scene_path(truth);
  return o;
}

HilTwinReport run_twin(const std::string& scene, const HilOptions& o) {
  const HilReport r = run_hil(load_scene(scene_path(scene)), o);
  EXPECT_TRUE(r.bit_exact);  // the host node: the offline estimator on the same readings, bit for bit
  EXPECT_TRUE(r.twin.has_value());
  return r.twin.value_or(HilTwinReport{});
}

// With a truth equal to the model and no noise, the filter holds the state
// exactly and no parameter moves: the model and its discretisation are the
// core's (the same frame, the same first-order hold of the ground).
TEST(Twin, ExactModelHeldExactly) {
  HilOptions o = twin(20.0);
  o.measure_noise_pct = 0;
  const HilTwinReport t = run_twin("elcentro_bare.toml", o);
  ASSERT_TRUE(t.roof_displacement_nrmse);
  EXPECT_LT(*t.roof_displacement_nrmse, 1e-9);
  EXPECT_LT(t.residual_max_mps2, 1e-9);
  for (double e : t.eta_k) EXPECT_NEAR(e, 1.0, 1e-6);
  EXPECT_FALSE(t.detected);
}

// A 10 % loss in story 3 of the bare frame, 5 % noise on floors 3, 6, 8, 10:
// found, in story 3, its size within 2 points, within 20 s of strong motion.
TEST(Twin, FindsAStoryLossInTheBareFrame) {
  HilOptions o = twin(30.0);
  o.truth_path = std::string(VINES_TEST_DATA_DIR) + "/twin_bare_story3_loss10.toml";
  const HilTwinReport t = run_twin("elcentro_bare.toml", o);
  ASSERT_TRUE(t.detected);
  ASSERT_TRUE(t.story && t.size && t.detect_delay_s);
  EXPECT_EQ(*t.story, 3);
  EXPECT_NEAR(*t.size, 0.10, 0.02);
  EXPECT_LT(*t.detect_delay_s, 20.0);
  EXPECT_NEAR(t.truth_story_scales[2], 0.9, 1e-12);
  EXPECT_EQ(t.caveat, "");
}

// A story at 1 % of its stiffness is beyond what the twin's model explains:
// the report says its verdict is not to be trusted (it named stories 2 and
// 6 with nothing said, issue 53). On the VI NES building, exact and
// noiseless, the residual alarm stays off: the impacts' samples, which the
// estimator has no model of, are left out of its RMS (it was on for 54 % of
// the steps).
TEST(Twin, SaysWhenItsModelCannotExplainTheMeasurements) {
  HilOptions o = twin(30.0);
  o.truth_path = std::string(VINES_TEST_DATA_DIR) + "/twin_bare_story3_at001.toml";
  const HilTwinReport t = run_twin("elcentro_bare.toml", o);
  EXPECT_NE(t.caveat.find("does not explain these measurements"), std::string::npos) << t.caveat;
  HilOptions exact = twin(20.0);
  exact.measure_noise_pct = 0;
  const HilTwinReport v = run_twin("elcentro_vines.toml", exact);
  EXPECT_GT(v.residual_max_mps2, 1.0);  // the impacts' residual is there...
  EXPECT_EQ(v.residual_alarm_steps, 0);  // ...and raises no alarm
  EXPECT_EQ(v.caveat, "");
}

// A truth whose story 3 loses 10 % 5 s into the record: the bench's truth
// switches there; the report says when, the factors before and after, and
// counts the detection's delay from the damage (not from strong motion).
TEST(Twin, DamageDuringTheRecord) {
  HilOptions o = twin(30.0);
  o.truth_path = std::string(VINES_TEST_DATA_DIR) + "/twin_bare_story3_damage_at5.toml";
  Scene sc = load_scene(scene_path("elcentro_bare.toml"));
  sc.duration_s = 30.0;
  const TwinBench tb = make_twin_bench(sc, o, load_excitation(sc, ""));
  ASSERT_TRUE(tb.truth.damage_time_s);
  EXPECT_EQ(*tb.truth.damage_time_s, 5.0);
  EXPECT_EQ(tb.truth.story_scale[2], 1.0);
  EXPECT_EQ(tb.truth.damaged_story_scale[2], 0.9);
  EXPECT_EQ(tb.truth.damaged_story_scale[3], 1.0);
  EXPECT_EQ(tb.delay_origin_s(), 5.0);
  EXPECT_LT(tb.strong_motion_start_s, 5.0);
  // Without [damage]: no time, the same factors after, the delay from strong motion.
  HilOptions plain = o;
  plain.truth_path = std::string(VINES_TEST_DATA_DIR) + "/twin_bare_story3_loss10.toml";
  const TwinBench tp = make_twin_bench(sc, plain, load_excitation(sc, ""));
  EXPECT_FALSE(tp.truth.damage_time_s);
  EXPECT_EQ(tp.truth.damaged_story_scale, tp.truth.story_scale);
  EXPECT_EQ(tp.delay_origin_s(), tp.strong_motion_start_s);

  const HilReport r = run_hil(load_scene(scene_path("elcentro_bare.toml")), o);
  ASSERT_TRUE(r.twin);
  const HilTwinReport& t = *r.twin;
  const nlohmann::json j = to_json(r)["twin"];
  SCOPED_TRACE(j.dump());
  EXPECT_EQ(j["truth_damage_time_s"], 5.0);
  EXPECT_EQ(j["truth_story_scales"][2], 1.0);
  EXPECT_EQ(j["truth_damaged_story_scales"][2], 0.9);
  ASSERT_TRUE(t.detected && t.story && t.size && t.detect_time_s && t.detect_delay_s);
  EXPECT_GT(*t.detect_time_s, 5.0);
  EXPECT_DOUBLE_EQ(*t.detect_delay_s, *t.detect_time_s - 5.0);
  ASSERT_TRUE(t.onset_s);  // the change test's candidate onset
  EXPECT_NEAR(*t.onset_s, 5.0, 2.0);
  EXPECT_EQ(t.stories, std::vector<int>{3});
  std::printf("damage at 5 s: story %d, loss %.3f, detected at %.3f s, delay %.3f s\n", *t.story, *t.size,
              *t.detect_time_s, *t.detect_delay_s);
  // Undamaged truth: null in the report, the damaged factors the same.
  const nlohmann::json u = to_json(run_hil(load_scene(scene_path("elcentro_bare.toml")), twin(1.0)))["twin"];
  EXPECT_TRUE(u["truth_damage_time_s"].is_null());
  EXPECT_EQ(u["truth_damaged_story_scales"], u["truth_story_scales"]);
}

// The VI NES building, its sphere started elsewhere than the model's and
// story 3 at 90 %: the impacts do not hide the loss; the roof is followed
// within 5 % NRMSE; the impacts the force estimate shows are the truth's.
TEST(Twin, VinesBuildingLossAndImpacts) {
  const HilTwinReport t = run_twin("elcentro_vines.toml", twin(0, "twin/truth_story3_loss10.toml"));
  ASSERT_TRUE(t.detected && t.story && t.size);
  EXPECT_EQ(*t.story, 3);
  EXPECT_NEAR(*t.size, 0.10, 0.02);
  ASSERT_TRUE(t.roof_displacement_nrmse);
  EXPECT_LT(*t.roof_displacement_nrmse, 0.05);
  EXPECT_EQ(t.device.kind, "vines");
  EXPECT_EQ(t.device.sphere, "moving");
  EXPECT_NEAR(static_cast<double>(t.device.impacts_estimated), static_cast<double>(t.device.contacts_truth),
              0.3 * static_cast<double>(t.device.contacts_truth));
  EXPECT_LT(std::fabs(t.device.added_mass_ratio), 0.3);
  // The impulse over the impacts alone: the estimate's noise between them
  // (about 5 kN) would add up to a third here.
  EXPECT_NEAR(t.device.impulse_estimated_ns, t.device.impulse_truth_ns, 0.1 * t.device.impulse_truth_ns);
}

// The range of the floor's absolute displacement in the truth: the ground's,
// integrated from the samples sent, plus the floor's own.
double truth_floor_travel(const Scene& sc, const HilOptions& o) {
  const Excitation ex = load_excitation(sc, "");
  const TwinBench tb = make_twin_bench(sc, o, ex);
  const double h = 1.0 / ex.rate_hz;
  double v = 0, u = 0, lo = 0, hi = 0;
  for (std::size_t k = 0; k < tb.truth.roof_x.size() && k < ex.samples.size(); ++k) {
    lo = std::min(lo, u + tb.truth.roof_x[k]), hi = std::max(hi, u + tb.truth.roof_x[k]);
    u += (v + 0.5 * ex.samples[k] * h) * h, v += ex.samples[k] * h;
  }
  return hi - lo;
}

// A jammed sphere moves with its floor: the floor's identified mass gains
// most of the sphere's, no impact is seen where the floor travelled far
// past the sphere's free travel (a free sphere at rest would have hit), and
// the sphere is reported stuck.
TEST(Twin, StuckSphereReported) {
  const HilOptions o = twin(0, "twin/truth_sphere_stuck.toml");
  const HilTwinReport t = run_twin("elcentro_vines.toml", o);
  EXPECT_EQ(t.device.sphere, "stuck");
  EXPECT_GT(t.device.added_mass_ratio, 0.5);
  EXPECT_EQ(t.device.contacts_truth, 0);
  EXPECT_EQ(t.device.impacts_estimated, 0);
  EXPECT_NEAR(t.device.free_travel_m, 2 * 0.4148, 1e-4);  // the scene's box (docs/model.md)
  const double travel = truth_floor_travel(load_scene(scene_path("elcentro_vines.toml")), o);
  EXPECT_NEAR(t.device.floor_travel_m, travel, 0.02 * travel);
  EXPECT_GT(t.device.floor_travel_m, 1.25 * t.device.free_travel_m);
}

// Weak shaking (El Centro at 0.05 g) never brings the sphere, at rest in the
// middle of its box, to a wall: no impact is seen in the estimate's noise,
// the floor travelled less than the sphere's free travel, and the sphere is
// still (not moving, not stuck).
TEST(Twin, SphereThatNeverHitIsStill) {
  Scene sc = load_scene(scene_path("elcentro_vines.toml"));
  sc.params.device.vines.start_at_left_wall = false;
  sc.params.device.vines.initial_position_m = 0;
  sc.target_pga_mps2 = 0.05 * 9.80665;
  sc.duration_s = 30;
  const HilReport r = run_hil(sc, twin(30));
  ASSERT_TRUE(r.twin);
  const HilTwinDevice& d = r.twin->device;
  EXPECT_EQ(d.contacts_truth, 0);
  EXPECT_EQ(d.impacts_estimated, 0);
  EXPECT_LT(d.floor_travel_m, d.free_travel_m);
  EXPECT_EQ(d.sphere, "still");
  EXPECT_EQ(d.impulse_estimated_ns, 0.0);
}

// A TMD 10 % low in frequency: its spring identified, the TMD reported
// detuned, its frequency within 3 points of the truth's.
TEST(Twin, DetunedTmdReported) {
  const HilTwinReport t = run_twin("elcentro_tmd.toml", twin(0, "twin/truth_tmd_detuned.toml"));
  EXPECT_EQ(t.device.kind, "tmd");
  EXPECT_TRUE(t.device.detuned);
  EXPECT_NEAR(t.device.truth_frequency_factor, 0.9, 1e-3);
  EXPECT_NEAR(t.device.frequency_factor, 0.9, 0.03);
}

// The estimator in float (the Cortex-M4F's) on the same image and readings
// as in double: the roof within 1e-3 of the double's peak, every factor
// within 0.005, the same decision. 30 s: on 20 s of this record the
// double's alarm is not sure to come (seeds 1-4 raise it at 9-20 s of 30).
TEST(Twin, FloatFollowsDouble) {
  Scene sc = load_scene(scene_path("elcentro_vines.toml"));
  sc.duration_s = 30;
  HilOptions o = twin(30.0, "twin/truth_story3_loss10.toml");
  const Excitation ex = load_excitation(sc, "");
  const TwinBench tb = make_twin_bench(sc, o, ex);
  auto f = std::make_unique<twin::Estimator<float, 10>>();
  auto d = std::make_unique<twin::Estimator<double, 10>>();
  f->image_begin(), d->image_begin();
  ASSERT_EQ(f->image_push(tb.design.image.data(), tb.design.image.size()), nullptr);
  ASSERT_EQ(d->image_push(tb.design.image.data(), tb.design.image.size()), nullptr);
  ASSERT_EQ(f->image_finish(), nullptr);
  ASSERT_EQ(d->image_finish(), nullptr);
  double peak = 0, diff = 0;
  for (std::size_t k = 0; k < ex.samples.size(); ++k) {
    const int ny = static_cast<int>(tb.y[k].size());
    if (k == 0) f->init(static_cast<float>(ex.samples[0]), tb.y[0].data(), ny), d->init(ex.samples[0], tb.y[0].data(), ny);
    else f->step(static_cast<float>(ex.samples[k]), tb.y[k].data(), ny), d->step(ex.samples[k], tb.y[k].data(), ny);
    peak = std::max(peak, std::fabs(d->x(9)));
    diff = std::max(diff, std::fabs(static_cast<double>(f->x(9)) - d->x(9)));
  }
  EXPECT_LT(diff, 1e-3 * peak);
  for (int j = 0; j < d->dims().np; ++j) EXPECT_NEAR(f->loss(j), d->loss(j), 0.005) << "parameter " << j;
  EXPECT_EQ(f->alarm_story(), d->alarm_story());
  EXPECT_EQ(d->alarm_story(), 3);
}

// A twin image damaged on its way is refused with the reason.
TEST(Twin, DamagedImageRefused) {
  Scene sc = load_scene(scene_path("elcentro_bare.toml"));
  sc.duration_s = 1;
  const TwinBench tb = make_twin_bench(sc, twin(1.0), load_excitation(sc, ""));
  const std::vector<std::uint8_t>& good = tb.design.image;
  auto refusal = [](std::vector<std::uint8_t> img) -> std::string {
    auto e = std::make_unique<twin::Estimator<double, 10>>();
    e->image_begin();
    const char* why = e->image_push(img.data(), img.size());
    if (!why) why = e->image_finish();
    return why ? why : "";
  };
  EXPECT_EQ(refusal(good), "");
  EXPECT_EQ(refusal(std::vector<std::uint8_t>(good.begin(), good.end() - 8)), "twin image: truncated");
  std::vector<std::uint8_t> bad = good;
  bad[0] = 'X';
  EXPECT_EQ(refusal(bad), "twin image: not a twin image");
  bad = good;
  for (int i = 0; i < 8; ++i) bad[bad.size() - 8 + i] = 0xff;  // a NaN
  EXPECT_EQ(refusal(bad), "twin image: a value is not finite");
  bad = good;
  bad.push_back(0);
  EXPECT_NE(refusal(bad), "");
}

// The boards' twin image runs the estimator alone, and the device images
// hold none: each refuses the other's work with the reason.
TEST(Twin, TwinImageAndDeviceImagesKeepToTheirWork) {
  Scene sc = load_scene(scene_path("elcentro_vines.toml"));
  sc.duration_s = 1;
  const TwinBench tb = make_twin_bench(sc, twin(1.0), load_excitation(sc, ""));
  const std::vector<std::uint8_t>& img = tb.design.image;
  link::NodeConfig c;
  c.scene = sc.params;
  c.mode = link::NodeMode::kTwin;
  c.estimator = link::TwinEstimator::kKalman;
  char msg[128] = "";

  auto node = std::make_unique<link::TwinPlant<double, 10>>();
  ASSERT_EQ(node->image_begin(static_cast<std::uint32_t>(img.size())), nullptr);
  ASSERT_EQ(node->image_push(img.data(), img.size()), nullptr);
  ASSERT_EQ(node->image_finish(), nullptr);
  EXPECT_TRUE(node->configure(c, msg, sizeof msg)) << msg;
  link::NodeConfig replay = c;
  replay.mode = link::NodeMode::kReplay;
  replay.estimator = link::TwinEstimator::kNone;
  EXPECT_FALSE(node->configure(replay, msg, sizeof msg));
  EXPECT_STREQ(msg, "mode: this node runs the twin estimator only (--mode twin --estimator kalman)");

  using Kuwabara = VinesDevice<ContactLaw::kKuwabara>;
  auto model = std::make_unique<Model<double, 10, Kuwabara>>();
  auto data = std::make_unique<Data<double, 10, Kuwabara>>();
  auto board = std::make_unique<link::ModelPlant<double, 10, Kuwabara>>(model.get(), data.get());
  ASSERT_EQ(board->image_begin(static_cast<std::uint32_t>(img.size())), nullptr);
  const char* why = board->image_push(img.data(), img.size());
  ASSERT_NE(why, nullptr);
  EXPECT_NE(std::string(why).find("holds no estimator"), std::string::npos) << why;
}

// Bad twin inputs: each refused, naming the input.
TEST(Twin, BadInputsRefused) {
  const Scene sc = load_scene(scene_path("elcentro_bare.toml"));
  auto refused = [&](HilOptions o, const std::string& what) {
    try {
      run_hil(sc, o);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  HilOptions o = twin(1.0);
  o.sensors = {0, 3};
  refused(o, "--sensors 0: a floor from 1 to 10");
  o.sensors = {11};
  refused(o, "--sensors 11: a floor from 1 to 10");
  o.sensors = {3, 3};
  refused(o, "--sensors 3: given twice");
  o.sensors = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  refused(o, "--sensors: at most 8 floors");
  o = twin(1.0);
  o.floors = {3, 6, 3};  // two x_3_m columns in --csv
  refused(o, "--floors 3: given twice");
  o = twin(1.0);
  o.truth_path = std::string(VINES_TEST_DATA_DIR) + "/twin_truth_3_stories.toml";
  refused(o, "frame.stories 3 differs");
  o.truth_path = std::string(VINES_TEST_DATA_DIR) + "/twin_truth_kobe.toml";
  refused(o, "its record (file, scale or pga) differs");
  o = twin(1.0);
  o.measure_noise_mps2 = 0.1;
  refused(o, "--measure-noise and --measure-noise-pct: give one of them");
  HilOptions replay;
  replay.node_command = VINES_EXE;
  replay.sensors = {3};
  refused(replay, "--sensors: a twin option");
  // A truth's damage after the run's end (1 s here); damage in the node's scene.
  o = twin(1.0);
  o.truth_path = std::string(VINES_TEST_DATA_DIR) + "/twin_bare_story3_damage_at5.toml";
  refused(o, "damage.time_s: 5 s is not inside the record as run (1 s, record.duration_s)");
  Scene damaged = sc;
  damaged.damage.time_s = 0.5;
  damaged.damage.stiffness_scales.assign(10, 0.9);
  for (HilMode mode : {HilMode::kTwin, HilMode::kReplay}) {
    HilOptions d = twin(1.0);
    d.mode = mode;
    if (mode != HilMode::kTwin) d.sensors.clear(), d.measure_noise_pct = 0;
    try {
      run_hil(damaged, d);
      ADD_FAILURE() << "accepted a node scene with [damage]";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("[damage]"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace vines::host
