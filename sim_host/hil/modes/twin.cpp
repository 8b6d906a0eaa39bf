#include "sim_host/hil/modes/twin.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/hil/modes/twin_baseline.hpp"
#include "sim_host/run/damage.hpp"
#include "sim_host/run/drive.hpp"
#include "vines/twin/image.hpp"

namespace vines::host {
namespace {

// The floors measured: --sensors, or the top floor.
std::vector<int> sensor_floors(const HilOptions& o, int n) {
  std::vector<int> s = o.sensors.empty() ? std::vector<int>{n} : o.sensors;
  if (s.size() > static_cast<std::size_t>(twin::kMaxSensors))
    throw std::runtime_error("--sensors: at most " + std::to_string(twin::kMaxSensors) + " floors");
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] < 1 || s[i] > n)
      throw std::runtime_error("--sensors " + std::to_string(s[i]) + ": a floor from 1 to " + std::to_string(n) +
                               " (the ground is the node's input)");
    if (std::find(s.begin(), s.begin() + static_cast<long>(i), s[i]) != s.begin() + static_cast<long>(i))
      throw std::runtime_error("--sensors " + std::to_string(s[i]) + ": given twice");
  }
  return s;
}

// The measured building's scene: --truth, or the node's own; then
// --truth-stiffness-scale. Same story count, sensor rate and samples.
Scene truth_scene(const Scene& scene, const HilOptions& o, const Excitation& ex) {
  if (o.truth_path.empty()) {
    Scene t = scene;
    t.params.frame.stiffness_scale *= o.truth_stiffness_scale;
    return t;
  }
  const std::string who = "--truth " + o.truth_path;
  Scene t = load_scene(o.truth_path);
  t.duration_s = scene.duration_s;
  t.params.frame.stiffness_scale *= o.truth_stiffness_scale;
  if (t.params.frame.stories != scene.params.frame.stories)
    throw std::runtime_error(who + ": frame.stories " + std::to_string(t.params.frame.stories) + " differs from " +
                             scene.path + "'s " + std::to_string(scene.params.frame.stories));
  if (t.params.loop.sensor_rate_hz != scene.params.loop.sensor_rate_hz)
    throw std::runtime_error(who + ": loop.sensor_rate_hz differs from " + scene.path + "'s");
  const Excitation tex = load_excitation(t, "");
  if (tex.samples != ex.samples)
    throw std::runtime_error(who + ": its record (file, scale or pga) differs from " + scene.path +
                             "'s: the truth is the same earthquake on another building");
  check_damage_time(t, static_cast<double>(ex.samples.size() - 1) / ex.rate_hz, who);
  return t;
}

// The record's 5 % Arias intensity time: where strong motion starts.
double arias_start(const std::vector<double>& a, double h) {
  double total = 0, run = 0;
  for (double v : a) total += v * v;
  for (std::size_t k = 0; k < a.size(); ++k)
    if ((run += a[k] * a[k]) >= 0.05 * total) return static_cast<double>(k) * h;
  return 0;
}

}  // namespace

TwinBench make_twin_bench(const Scene& scene, const HilOptions& o, const Excitation& ex) {
  TwinBench tb;
  const int n = scene.params.frame.stories;
  const double h = 1.0 / scene.params.loop.sensor_rate_hz;
  tb.sensors = sensor_floors(o, n);
  if (o.measure_noise_mps2 > 0 && o.measure_noise_pct > 0)
    throw std::runtime_error("--measure-noise and --measure-noise-pct: give one of them");
  if (scene.damage.present())
    throw std::runtime_error(scene.path + ": [damage]: the node's scene is the nominal model the twin "
                             "carries; damage goes in the measured building's scene (--truth TRUTH.toml)");
  const Scene truth = truth_scene(scene, o, ex);
  TwinTruth& tr = tb.truth;
  tr.path = o.truth_path;
  const SceneParams after = damaged_params(truth.params, truth.damage);
  for (int i = 0; i < n; ++i) {
    tr.story_scale.push_back(truth.params.frame.stiffness_scale * truth.params.frame.stiffness_scales[i]);
    tr.damaged_story_scale.push_back(after.frame.stiffness_scale * after.frame.stiffness_scales[i]);
  }
  if (truth.damage.present())
    tr.damage_time_s = static_cast<double>(damage_sample(truth.damage.time_s, ex.rate_hz)) * h;

  // The measured building, step by step: every floor's absolute acceleration
  // (with [damage], the damaged building from its time on).
  const std::string what = o.truth_path.empty() ? scene.path + " (truth)" : "--truth " + o.truth_path;
  DamagedRun run(truth.params, truth.damage, Scalar::kDouble, ex.rate_hz, what);
  const auto K = ex.samples.size();
  std::vector<std::vector<double>> acc(K);
  const bool vines = truth.params.device.kind == DeviceKind::kVines;
  hal::RecordSource src(ex.samples, ex.rate_hz);
  drive(run, src, 1, [&](std::size_t k) {
    const Snapshot s = run.engine().snapshot();
    acc[k].assign(s.acc.begin(), s.acc.begin() + n);
    tr.roof_x.push_back(s.x[static_cast<std::size_t>(n - 1)]);
    tr.device_force.push_back(vines ? -s.contact_force : 0.0);
  });
  const ModelInfo ti = run.engine().info();
  tr.contacts = run.engine().totals().count.contacts;

  // The sensors: noise (absolute, or a share of each channel's RMS), a bias
  // drawn once per sensor, ADC quantisation; all from the seed.
  const std::size_t ny = tb.sensors.size();
  std::mt19937_64 rng(o.seed + 17);
  std::normal_distribution<double> unit(0.0, 1.0);
  auto channel_sd = [&](int floor) {
    if (o.measure_noise_pct <= 0) return o.measure_noise_mps2;
    double ss = 0;
    for (const auto& a : acc) ss += a[static_cast<std::size_t>(floor - 1)] * a[static_cast<std::size_t>(floor - 1)];
    return 0.01 * o.measure_noise_pct * std::sqrt(ss / static_cast<double>(K));
  };
  std::vector<double> bias(ny + 1);
  for (std::size_t i = 0; i <= ny; ++i) bias[i] = o.measure_bias_mps2 * unit(rng);
  for (std::size_t i = 0; i < ny; ++i) tb.noise_sd.push_back(channel_sd(tb.sensors[i]));
  const double top_sd = channel_sd(n);
  auto read = [&](double v, double sd, double b) {
    const double m = v + b + sd * unit(rng);
    return o.adc_lsb_mps2 > 0 ? o.adc_lsb_mps2 * std::nearbyint(m / o.adc_lsb_mps2) : m;
  };
  tb.y.resize(K);
  for (std::size_t k = 0; k < K; ++k) {
    tb.top.push_back(read(acc[k][static_cast<std::size_t>(n - 1)], top_sd, bias[ny]));
    for (std::size_t i = 0; i < ny; ++i)
      tb.y[k].push_back(read(acc[k][static_cast<std::size_t>(tb.sensors[i] - 1)], tb.noise_sd[i], bias[i]));
  }
  tb.strong_motion_start_s = arias_start(ex.samples, h);

  // The node's estimator, designed on the node's scene (the nominal model).
  const std::unique_ptr<Engine> nominal = build_engine(scene.params, Scalar::kDouble, scene.path);
  const ModelInfo ni = nominal->info();
  tr.particle_mass = ni.vines.mass;  // the sphere the node's scene designs
  tr.particle_gap = ni.vines.gap;
  if (ni.tmd.omega > 0 && truth.params.device.kind == DeviceKind::kTmd) tr.tmd_frequency_factor = ti.tmd.omega / ni.tmd.omega;
  if (o.estimator == HilEstimator::kKalman) {
    TwinBaselineStats base;
    if (!o.baseline_path.empty()) base = load_twin_baseline(o.baseline_path, twin_building(scene, o), o.tuning);
    tb.design = design_twin(scene.params, ni, tb.sensors, tb.noise_sd, o.tuning, o.baseline_path.empty() ? nullptr : &base);
  }
  return tb;
}

}  // namespace vines::host
