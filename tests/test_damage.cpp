// Damage that strikes during the earthquake (a scene's [damage]): `vines run`
// hands the run to the damaged model at damage.time_s from the same physical
// state. Checked against the closed form of a damped oscillator, bit for bit
// against a run without [damage] when nothing changes, and by the energy
// balance across the switch.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "host/record.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {
namespace {

std::string scene_path(const std::string& name) { return std::string(VINES_SOURCE_DIR) + "/data/scenes/" + name; }

// One story, m = 1e5 kg, k = 4e6 N/m, C = c_k K; a 0.2 s pulse of ground
// acceleration, then 20 s of none: free vibration.
const double kM = 1e5, kK = 4e6, kCk = 0.002;
const std::string kOneStory = R"(
[frame]
preset = "custom"
masses_kg = [1e5]
stiffnesses_n_per_m = [4e6]
damping = "stiffness"
stiffness_damping_s = 0.002
[record]
path = "pulse"
[loop]
sensor_rate_hz = 1000.0
energy_ledger = true
[output]
rate_hz = 1000.0
)";

Excitation pulse(const Scene& s) {
  hal::Record r;
  r.path = "pulse";
  r.dt_s = 0.01;
  r.accel_mps2.assign(2000, 0.0);
  for (int i = 0; i <= 20; ++i) r.accel_mps2[static_cast<std::size_t>(i)] = 0.5;
  return excitation_from_record(s, r);
}

// Two snapshots equal bit for bit, field by field (not their padding).
bool same(const Snapshot& a, const Snapshot& b) {
  const auto bits = [](const double* x, const double* y, std::size_t n) { return std::memcmp(x, y, n * sizeof(double)) == 0; };
  return bits(&a.t, &b.t, 1) && bits(&a.ag, &b.ag, 1) && bits(a.x.data(), b.x.data(), a.x.size()) &&
         bits(a.v.data(), b.v.data(), a.v.size()) && bits(a.acc.data(), b.acc.data(), a.acc.size()) &&
         bits(a.drift.data(), b.drift.data(), a.drift.size()) && bits(&a.elastic_energy, &b.elastic_energy, 1) &&
         bits(&a.particle_x, &b.particle_x, 1) && bits(&a.particle_v, &b.particle_v, 1) &&
         bits(&a.wall_left, &b.wall_left, 1) && bits(&a.wall_right, &b.wall_right, 1) &&
         bits(&a.contact_force, &b.contact_force, 1) && a.mode == b.mode && bits(&a.tmd_x, &b.tmd_x, 1) &&
         bits(&a.tmd_v, &b.tmd_v, 1);
}

RunReport run_kept(const Scene& s, const Excitation& ex) {
  RunOptions o;
  o.keep_series = true;
  return run_scene(s, ex, o);
}

// x(t0 + tau) of m x'' + c x' + k x = 0 from x0, v0 at t0.
double free_x(double k, double x0, double v0, double tau) {
  const double w0 = std::sqrt(k / kM), zeta = kCk * k / (2 * kM * w0), wd = w0 * std::sqrt(1 - zeta * zeta);
  return std::exp(-zeta * w0 * tau) * (x0 * std::cos(wd * tau) + (v0 + zeta * w0 * x0) / wd * std::sin(wd * tau));
}

double damped_period(double k) {
  const double w0 = std::sqrt(k / kM), zeta = kCk * k / (2 * kM * w0);
  return 2 * M_PI / (w0 * std::sqrt(1 - zeta * zeta));
}

// The largest |x - closed form| over rows [from, to), the closed form
// started from row `from`'s state; and the mean period between upward zero
// crossings in those rows.
struct Fit {
  double err = 0, amp = 0, period = 0;
};
Fit fit(const std::vector<Snapshot>& rows, std::size_t from, std::size_t to, double k) {
  Fit f;
  const double t0 = rows[from].t, x0 = rows[from].x[0], v0 = rows[from].v[0];
  std::vector<double> ups;
  for (std::size_t i = from; i < to; ++i) {
    f.err = std::max(f.err, std::fabs(rows[i].x[0] - free_x(k, x0, v0, rows[i].t - t0)));
    f.amp = std::max(f.amp, std::fabs(rows[i].x[0]));
    if (i > from && rows[i - 1].x[0] < 0 && rows[i].x[0] >= 0)
      ups.push_back(rows[i - 1].t + (rows[i].t - rows[i - 1].t) * -rows[i - 1].x[0] / (rows[i].x[0] - rows[i - 1].x[0]));
  }
  if (ups.size() >= 2) f.period = (ups.back() - ups.front()) / static_cast<double>(ups.size() - 1);
  return f;
}

// The story loses 36 % at 5 s: before, the undamaged oscillator; after,
// the damaged one (period 2 pi / (0.8 w0), its damping scaled too) from the
// state at 5 s, both to 1e-9 of the amplitude.
TEST(Damage, OneStoryFreeVibration) {
  const Scene s = parse_scene(kOneStory + "[damage]\ntime_s = 5.0\nstiffness_scales = [0.64]\n", "one_story.toml");
  const RunReport r = run_kept(s, pulse(s));
  ASSERT_EQ(r.series.size(), 20001u);
  const std::size_t kd = 5000;
  EXPECT_EQ(r.series[kd].t, 5.0);
  const Fit before = fit(r.series, 1000, kd + 1, kK), after = fit(r.series, kd, r.series.size(), 0.64 * kK);
  std::printf("before: error %.3g of %.3g m, period %.9f s (closed form %.9f); after: error %.3g of %.3g m, period "
              "%.9f s (%.9f)\n",
              before.err, before.amp, before.period, damped_period(kK), after.err, after.amp, after.period,
              damped_period(0.64 * kK));
  EXPECT_LT(before.err, 1e-9 * before.amp) << before.err << " of " << before.amp;
  EXPECT_LT(after.err, 1e-9 * after.amp) << after.err << " of " << after.amp;
  EXPECT_NEAR(before.period, damped_period(kK), 1e-6 * damped_period(kK));
  EXPECT_NEAR(after.period, damped_period(0.64 * kK), 1e-6 * damped_period(0.64 * kK));
  EXPECT_NEAR(after.period / before.period, 1.25, 1e-4);  // sqrt(1 / 0.64), damping aside
  // The summary says so; the strain energy the story lost counts as energy put in.
  const nlohmann::json j = r.to_json();
  EXPECT_EQ(j["damage"]["time_s"], 5.0);
  EXPECT_EQ(j["damage"]["switch_s"], 5.0);
  EXPECT_NEAR(j["damage"]["frequency_hz_after"][0].get<double>(), 0.8 * j["modal"]["frequency_hz"][0].get<double>(),
              1e-12);
  EXPECT_LT(r.totals.ledger.initial, 0.0);
  EXPECT_LT(r.totals.ledger.relative_residual(), 1e-12);
  // The same story damaged from the start: the damaged oscillator throughout.
  const Scene from0 = parse_scene(kOneStory + "[damage]\ntime_s = 0\nstiffness_scales = [0.64]\n", "one_story.toml");
  const RunReport r0 = run_kept(from0, pulse(from0));
  const Fit all = fit(r0.series, 1000, r0.series.size(), 0.64 * kK);
  EXPECT_LT(all.err, 1e-9 * all.amp);
}

// Every factor 1: the run is the run without [damage], bit for bit.
TEST(Damage, EveryFactorOneIsTheSameRun) {
  for (const char* file : {"elcentro_vines.toml", "elcentro_tmd.toml"}) {
    SCOPED_TRACE(file);
    Scene plain = load_scene(scene_path(file));
    plain.duration_s = 10.0;
    Scene ones = plain;
    ones.damage.time_s = 4.0;
    ones.damage.stiffness_scales.assign(10, 1.0);
    const RunReport a = run_kept(plain, load_excitation(plain, "")), b = run_kept(ones, load_excitation(ones, ""));
    ASSERT_EQ(a.series.size(), b.series.size());
    for (std::size_t k = 0; k < a.series.size(); ++k)
      ASSERT_TRUE(same(a.series[k], b.series[k])) << "row " << k;
    nlohmann::json ja = a.to_json(), jb = b.to_json();
    for (const char* key : {"wall_time_s", "damage"}) ja.erase(key), jb.erase(key);
    EXPECT_EQ(ja, jb);
    EXPECT_TRUE(b.to_json()["damage"].is_object());
  }
}

// El Centro with story 3 at 80 % from 5 s: the same rows as the undamaged
// run up to the switch and the same floors at it (to rounding), then
// another response; the energy balance as tight as without damage, the
// bare frame damaged too.
TEST(Damage, ElCentroBalanceAndContinuity) {
  for (const char* file : {"elcentro_vines.toml", "elcentro_tmd.toml", "elcentro_bare.toml"}) {
    SCOPED_TRACE(file);
    const Scene plain = load_scene(scene_path(file));
    Scene hit = plain;
    hit.damage.time_s = 5.0;
    hit.damage.stiffness_scales = {1, 1, 0.8, 1, 1, 1, 1, 1, 1, 1};
    const Excitation ex = load_excitation(plain, "");
    const RunReport a = run_kept(plain, ex), b = run_kept(hit, ex);
    const std::size_t kd = 500;  // 5 s at the 100 Hz output rate
    ASSERT_EQ(b.series[kd].t, 5.0);
    for (std::size_t k = 0; k < kd; ++k) ASSERT_TRUE(same(a.series[k], b.series[k])) << "row " << k;
    double scale = 0;
    for (int i = 0; i < 10; ++i) scale = std::max(scale, std::fabs(a.series[kd].x[i]));
    for (int i = 0; i < 10; ++i) {
      EXPECT_NEAR(b.series[kd].x[i], a.series[kd].x[i], 1e-12 * scale);
      EXPECT_NEAR(b.series[kd].v[i], a.series[kd].v[i], 1e-11 * scale);
    }
    EXPECT_NE(b.totals.peak_top, a.totals.peak_top);
    const double ra = a.totals.ledger.relative_residual(), rb = b.totals.ledger.relative_residual();
    std::printf("%s: energy residual %.3g undamaged, %.3g damaged; initial %.6g J; peak top %.6f -> %.6f m\n", file,
                ra, rb, b.totals.ledger.initial, a.totals.peak_top, b.totals.peak_top);
    EXPECT_LT(rb, std::max(10 * ra, 1e-11));
    EXPECT_LT(rb, 1e-9);
    EXPECT_LT(b.totals.ledger.initial, 0.0);  // the story's strain energy drops at the switch
    if (a.bare) {
      ASSERT_TRUE(b.bare);
      EXPECT_NE(b.bare->peak_top, a.bare->peak_top);
      EXPECT_LT(b.bare->ledger.relative_residual(), 1e-9);
    }
    EXPECT_EQ(b.to_json()["damage"]["stiffness_scales"][2], 0.8);
    EXPECT_TRUE(a.to_json()["damage"].is_null());
  }
}

// The VI NES's sphere in contact with a wall at the switch: the contact
// goes on across it, the balance holds.
TEST(Damage, SwitchDuringAContact) {
  Scene plain = load_scene(scene_path("elcentro_vines.toml"));
  plain.output.rate_hz = 1000.0;
  plain.duration_s = 20.0;
  const Excitation ex = load_excitation(plain, "");
  const RunReport a = run_kept(plain, ex);
  std::size_t k = 3000;
  while (k < a.series.size() && a.series[k].mode == 0) ++k;
  ASSERT_LT(k, a.series.size()) << "no contact after 3 s";
  Scene hit = plain;
  hit.damage.time_s = a.series[k].t;
  hit.damage.stiffness_scales = {0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9};
  const RunReport b = run_kept(hit, ex);
  EXPECT_EQ(b.series[k].mode, a.series[k].mode);
  EXPECT_EQ(b.series[k].particle_x, a.series[k].particle_x);
  EXPECT_NEAR(b.series[k].contact_force, a.series[k].contact_force, 1e-9 * std::fabs(a.series[k].contact_force));
  std::printf("contact at %.3f s: energy residual %.3g (undamaged %.3g), %lld contacts (undamaged %lld)\n",
              a.series[k].t, b.totals.ledger.relative_residual(), a.totals.ledger.relative_residual(),
              static_cast<long long>(b.totals.count.contacts), static_cast<long long>(a.totals.count.contacts));
  EXPECT_LT(b.totals.ledger.relative_residual(), 1e-9);
  EXPECT_TRUE(b.status.ok());
}

// Refused: a time the run never reaches (the record, or duration_s), and
// fixed point (no change of model there); every factor 1 runs in fixed point.
TEST(Damage, Refusals) {
  Scene s = load_scene(scene_path("elcentro_bare.toml"));
  s.duration_s = 10.0;
  s.damage.time_s = 12.0;
  s.damage.stiffness_scales.assign(10, 0.9);
  try {
    run_scene(s, RunOptions{});
    ADD_FAILURE() << "accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    for (const char* part : {"elcentro_bare.toml", "damage.time_s", "12 s", "10 s", "record.duration_s"})
      EXPECT_NE(m.find(part), std::string::npos) << m << "\nlacks: " << part;
  }
  s.duration_s = 0;
  s.damage.time_s = 60.0;  // El Centro: 53.74 s
  RunOptions to_dir;
  to_dir.out_dir = (std::filesystem::temp_directory_path() / ("vines_damage_" + std::to_string(::getpid()))).string();
  EXPECT_THROW(run_scene(s, to_dir), SceneError);
  EXPECT_FALSE(std::filesystem::exists(to_dir.out_dir));  // refused before the folder is claimed

  Scene f = load_scene(scene_path("elcentro_vines_fixed.toml"));
  f.duration_s = 2.0;
  f.damage.time_s = 1.0;
  f.damage.stiffness_scales.assign(10, 0.9);
  try {
    run_scene(f, to_dir);
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not available in fixed point"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(to_dir.out_dir));
  f.damage.stiffness_scales.assign(10, 1.0);
  EXPECT_NO_THROW(run_scene(f, RunOptions{}));
}

}  // namespace
}  // namespace vines::host
