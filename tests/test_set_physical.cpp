// The physical state set on the host Engine (sim_host/engines/engine.hpp):
// set_physical() (vines/set_state.hpp) reproduces a snapshot from its own
// outputs, gives the closed-form free vibration of a one-story frame and of
// a mode of the paper's frame, keeps E_e and the energy balance across the
// change, and refuses what it cannot set.
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

// The physical state a snapshot reads, set.
PhysicalState physical(const Snapshot& s, int stories, DeviceKind kind) {
  PhysicalState ps;
  for (int i = 0; i < stories; ++i) {
    ps.x[i] = s.x[i];
    ps.v[i] = s.v[i];
  }
  if (kind == DeviceKind::kVines) {
    ps.particle_x = s.particle_x;
    ps.particle_v = s.particle_v;
  }
  if (kind == DeviceKind::kTmd) {
    ps.tmd_x = s.tmd_x;
    ps.tmd_v = s.tmd_v;
  }
  return ps;
}

// Relative difference against a scale.
double rel(double a, double b, double scale) { return std::fabs(a - b) / scale; }

// (a) A snapshot's own state set on a copy of the engine gives the snapshot
// back (to rounding: the floors are solved for the modes) and the run goes on
// as the uninterrupted one, to a small tolerance.
TEST(SetPhysical, ReproducesTheSnapshot) {
  const std::vector<double> a = samples();
  for (DeviceKind kind : {DeviceKind::kNone, DeviceKind::kTmd, DeviceKind::kVines}) {
    const SceneParams p = test::paper_scene(kind);
    const auto one = built(p, Scalar::kDouble), two = built(p, Scalar::kDouble);
    one->init(a[0]);
    std::size_t k = 1;
    for (; k < 3001; ++k) one->step(a[k]);
    while (kind == DeviceKind::kVines && one->probe().mode != 0) one->step(a[k++]);  // free flight
    const std::vector<std::uint8_t> st = one->state();
    ASSERT_EQ(two->load_state(st.data(), st.size()), "");
    const Snapshot s = one->snapshot();
    const double xs = one->totals().peak_top, vs = one->totals().peak_top_velocity;
    ASSERT_EQ(two->set_physical(physical(s, 10, kind)), "") << device_name(kind);
    const Snapshot t = two->snapshot();
    double worst = 0;
    for (int i = 0; i < 10; ++i) {
      worst = std::fmax(worst, rel(s.x[i], t.x[i], xs));
      worst = std::fmax(worst, rel(s.v[i], t.v[i], vs));
      worst = std::fmax(worst, rel(s.acc[i], t.acc[i], std::fabs(s.acc[9]) + 1.0));
    }
    worst = std::fmax(worst, rel(s.elastic_energy, t.elastic_energy, s.elastic_energy));
    worst = std::fmax(worst, rel(s.particle_x, t.particle_x, xs));
    worst = std::fmax(worst, rel(s.particle_v, t.particle_v, vs));
    worst = std::fmax(worst, rel(s.tmd_x, t.tmd_x, xs));
    worst = std::fmax(worst, rel(s.tmd_v, t.tmd_v, vs));
    EXPECT_LT(worst, 1e-12) << device_name(kind);
    EXPECT_EQ(s.t, t.t);
    EXPECT_EQ(one->totals().count.steps, two->totals().count.steps);
    // 0.3 s on.
    double after = 0;
    for (std::size_t j = 0; j < 300; ++j, ++k) {
      one->step(a[k]);
      two->step(a[k]);
      const Snapshot u = one->snapshot(), w = two->snapshot();
      for (int i = 0; i < 10; ++i) after = std::fmax(after, rel(u.x[i], w.x[i], xs));
      after = std::fmax(after, rel(u.particle_x, w.particle_x, xs));
    }
    EXPECT_LT(after, 1e-9) << device_name(kind);
    std::printf("%s: the snapshot back to %.2e, 0.3 s on to %.2e of the peak\n", device_name(kind), worst, after);
  }
}

// Damped free vibration from x0 at rest: x(t) / x0.
double free_decay(double w, double zeta, double t) {
  const double wd = w * std::sqrt(1.0 - zeta * zeta);
  return std::exp(-zeta * w * t) * (std::cos(wd * t) + zeta * w / wd * std::sin(wd * t));
}

// (b) A one-story frame (m, k, C = c_k K) set to x0 at rest, no ground
// motion: the closed-form damped free vibration, omega = sqrt(k / m), zeta =
// c_k omega / 2; and the energy put in is (1/2) k x0^2.
TEST(SetPhysical, OneStoryFreeVibrationIsClosedForm) {
  SceneParams p = test::paper_scene(DeviceKind::kNone);
  p.frame.stories = 1;
  const double m = 2000.0, k = 8.0e5, ck = 0.002, x0 = 0.012;  // omega 20 rad/s, zeta 0.02
  p.frame.mass_kg[0] = m;
  p.frame.stiffness_n_per_m[0] = k;
  p.frame.damping = DampingRule::kStiffnessProportional;
  p.frame.stiffness_damping_s = ck;
  const double w = std::sqrt(k / m), zeta = ck * w / 2;
  const auto eng = built(p, Scalar::kDouble);
  eng->init(0.0);
  PhysicalState ps;
  ps.x[0] = x0;
  ps.v[0] = 0.0;
  ASSERT_EQ(eng->set_physical(ps), "");
  EXPECT_NEAR(eng->totals().ledger.initial, 0.5 * k * x0 * x0, 1e-12 * k * x0 * x0);
  double worst = 0;
  for (int j = 1; j <= 3000; ++j) {
    eng->step(0.0);
    const Snapshot s = eng->snapshot();
    worst = std::fmax(worst, std::fabs(s.x[0] - x0 * free_decay(w, zeta, s.t)) / x0);
  }
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(eng->totals().ledger.relative_residual(), 1e-12);
  std::printf("one story, 3 s: %.2e of x0\n", worst);
}

// (b) The paper's frame set to its second mode's shape at rest: every floor
// decays as that mode (info(): frequency, damping ratio, shape).
TEST(SetPhysical, ModeShapeDecaysAsItsMode) {
  SceneParams p = test::paper_scene(DeviceKind::kNone);
  const auto eng = built(p, Scalar::kDouble);
  const ModelInfo info = eng->info();
  const int j = 1;
  const double w = 2 * M_PI * info.frequency_hz[j], zeta = info.zeta[j];
  double top = 0;
  for (int i = 0; i < 10; ++i) top = std::fmax(top, std::fabs(info.mode_shapes[j][i]));
  const double scale = 0.02 / top;
  eng->init(0.0);
  PhysicalState ps;
  for (int i = 0; i < 10; ++i) {
    ps.x[i] = scale * info.mode_shapes[j][i];
    ps.v[i] = 0.0;
  }
  ASSERT_EQ(eng->set_physical(ps), "");
  double worst = 0;
  for (int n = 1; n <= 2000; ++n) {
    eng->step(0.0);
    const Snapshot s = eng->snapshot();
    for (int i = 0; i < 10; ++i) worst = std::fmax(worst, std::fabs(s.x[i] - ps.x[i] * free_decay(w, zeta, s.t)) / 0.02);
  }
  EXPECT_LT(worst, 1e-9);
  std::printf("mode 2 (%.3f Hz, zeta %.4f), 2 s: %.2e of its peak\n", info.frequency_hz[j], zeta, worst);
}

// (c) What set_physical refuses, naming the field; nothing changes.
TEST(SetPhysical, Refusals) {
  const std::vector<double> a = samples();
  const auto eng = built(test::paper_scene(DeviceKind::kVines), Scalar::kDouble);
  eng->init(a[0]);
  eng->run(a.data() + 1, 1500);
  const std::vector<std::uint8_t> before = eng->state();
  const Snapshot s = eng->snapshot();
  PhysicalState outside;
  outside.particle_x = s.wall_right + 1e-3;
  PhysicalState on_wall;  // just past the left wall
  on_wall.particle_x = s.wall_left - 1e-7;
  PhysicalState moved;  // the floors moved under the particle past a wall
  for (int i = 0; i < 10; ++i) moved.x[i] = s.x[i] + (s.wall_right - s.wall_left);
  PhysicalState partly;
  partly.x[0] = 0.01;
  partly.x[3] = 0.02;
  PhysicalState infinite_v;
  for (int i = 0; i < 10; ++i) infinite_v.v[i] = i == 4 ? INFINITY : 0.0;
  PhysicalState tmd;
  tmd.tmd_x = 0.01;
  const struct {
    PhysicalState ps;
    std::vector<const char*> parts;
  } refused[] = {{outside, {"particle_x", "not strictly between the walls"}},
                 {on_wall, {"particle_x", "not strictly between the walls"}},
                 {moved, {"particle_x", "not strictly between the walls"}},
                 {partly, {"x: give all 10 floors or none", "floor 2 is NaN"}},
                 {infinite_v, {"v: floor 5 is not finite"}},
                 {tmd, {"tmd_x", "no such device"}}};
  for (const auto& r : refused) {
    const std::string why = eng->set_physical(r.ps);
    std::printf("refused: %s\n", why.c_str());
    for (const char* part : r.parts) EXPECT_TRUE(has(why, part)) << why << "\nlacks: " << part;
    EXPECT_EQ(eng->state(), before) << why;
  }
  PhysicalState nothing;  // all NaN: nothing to change, but the particle is put in free flight
  EXPECT_EQ(eng->set_physical(nothing), "");

  // Fixed point: refused, with the reason.
  const Scene sc = load_scene(kScenes + "elcentro_vines_fixed.toml");
  const auto fixed = built(sc.params, Scalar::kFixed);
  fixed->init(0);
  EXPECT_TRUE(has(fixed->set_physical(nothing), "not available in fixed point"));
}

// (d) Across a change of state the energy balance holds (the change counts as
// energy put in) and E_e so far is kept, then goes on.
TEST(SetPhysical, KeepsTheLedgerAndElasticEnergy) {
  const std::vector<double> a = samples();
  for (DeviceKind kind : {DeviceKind::kNone, DeviceKind::kTmd, DeviceKind::kVines}) {
    const auto eng = built(test::paper_scene(kind), Scalar::kDouble);
    eng->init(a[0]);
    std::size_t k = 1;
    for (; k < 3001; ++k) eng->step(a[k]);
    while (kind == DeviceKind::kVines && eng->probe().mode != 0) eng->step(a[k++]);
    const Snapshot s = eng->snapshot();
    const Ledger l0 = eng->totals().ledger;
    const double residual_before = l0.relative_residual();
    PhysicalState ps = physical(s, 10, kind);
    for (int i = 0; i < 10; ++i) {
      ps.x[i] *= 1.3;
      ps.v[i] *= -0.7;
    }
    if (kind == DeviceKind::kVines) {
      ps.particle_x = 1.3 * s.x[9] + 0.25 * (s.wall_right - s.wall_left) * 0.5;
      ps.particle_v = 0.5;
    }
    if (kind == DeviceKind::kTmd) ps.tmd_x = 1.3 * s.tmd_x;
    ASSERT_EQ(eng->set_physical(ps), "") << device_name(kind);
    const Snapshot t = eng->snapshot();
    const Ledger l1 = eng->totals().ledger;
    EXPECT_NEAR(t.elastic_energy, s.elastic_energy, 1e-12 * s.elastic_energy) << device_name(kind);
    const double stored0 = l0.kinetic + l0.strain + l0.device, stored1 = l1.kinetic + l1.strain + l1.device;
    EXPECT_NEAR(l1.initial - l0.initial, stored1 - stored0, 1e-12 * l0.max_input) << device_name(kind);
    EXPECT_NEAR(l1.residual, l0.residual, 1e-12 * l0.max_input) << device_name(kind);
    for (int i = 0; i < 10; ++i) EXPECT_NEAR(t.x[i], ps.x[i], 1e-15 * std::fabs(s.x[9]) * 100) << device_name(kind);
    if (kind == DeviceKind::kVines) {
      EXPECT_EQ(t.mode, 0);
      EXPECT_EQ(t.contact_force, 0.0);
      EXPECT_NEAR(t.particle_x, ps.particle_x, 1e-14);
      EXPECT_EQ(t.particle_v, 0.5);
    }
    for (; k < a.size(); ++k) eng->step(a[k]);
    const RunTotals r = eng->totals();
    EXPECT_LT(r.ledger.relative_residual(), 1e-9) << device_name(kind);
    EXPECT_GT(r.elastic_energy, t.elastic_energy) << device_name(kind);
    std::printf("%s: relative residual %.2e before, %.2e at the end; energy put in %.4g J\n", device_name(kind),
                residual_before, r.ledger.relative_residual(), l1.initial - l0.initial);
  }
}

// In float, a snapshot's own state set reproduces it to the scalar's rounding.
TEST(SetPhysical, FloatReproducesTheSnapshot) {
  const std::vector<double> a = samples();
  const SceneParams p = test::paper_scene(DeviceKind::kVines);
  const auto eng = built(p, Scalar::kFloat);
  eng->init(a[0]);
  std::size_t k = 1;
  for (; k < 2001; ++k) eng->step(a[k]);
  while (eng->probe().mode != 0) eng->step(a[k++]);
  const Snapshot s = eng->snapshot();
  ASSERT_EQ(eng->set_physical(physical(s, 10, DeviceKind::kVines)), "");
  const Snapshot t = eng->snapshot();
  const double xs = eng->totals().peak_top;
  for (int i = 0; i < 10; ++i) EXPECT_LT(rel(s.x[i], t.x[i], xs), 1e-5) << i;
  EXPECT_LT(rel(s.particle_x, t.particle_x, xs), 1e-6);
  EXPECT_NEAR(t.elastic_energy, s.elastic_energy, 1e-6 * s.elastic_energy);
}

}  // namespace
