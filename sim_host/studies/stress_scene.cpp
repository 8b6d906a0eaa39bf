// Random scenes for `vines stress`: the records, the draw of one case from
// (seed, index), its ground-motion window, and the case as a scene file.
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "sim_host/engines/engine.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/scene/names.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/studies/stress.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
constexpr double kPi = 3.14159265358979323846;

// The records of the ground-motion folder and their formats (SOURCES.md).
struct RecordFile {
  const char* file;
  hal::RecordFormat format;
  hal::Units units;
  int column;
};
constexpr RecordFile kRecordFiles[] = {
    {"elcentro_1940_ns_2688pts_dt002_time_g.dat", hal::RecordFormat::kTimeAccel, hal::Units::kG, 1},
    {"elcentro_1940_ns_peknold_dt002.at2", hal::RecordFormat::kAt2, hal::Units::kG, 1},
    {"elcentro_1940_ns_peer_legacy_I-ELC180_dt001.at2", hal::RecordFormat::kAt2, hal::Units::kG, 1},
    {"elcentro_1940_ns_peer_nga_west2_rsn6_I-ELC180.at2", hal::RecordFormat::kAt2, hal::Units::kG, 1},
    {"taft_1952_kern_county_TAF021_nga_west2_rsn15.at2", hal::RecordFormat::kAt2, hal::Units::kG, 1},
    {"kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2", hal::RecordFormat::kAt2, hal::Units::kG, 1},
    {"northridge_1994_rinaldi_228_nga_rsn1063.at2", hal::RecordFormat::kAt2, hal::Units::kG, 1},
    {"northridge_1994_sylmar_county_hospital_ns_time_ms2.dat", hal::RecordFormat::kTimeAccel,
     hal::Units::kMps2, 1},
    {"lomaprieta_1989_corralitos_CLS000_nga_west2_rsn753.at2", hal::RecordFormat::kAt2, hal::Units::kG, 1},
    {"mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt", hal::RecordFormat::kTimeAccel, hal::Units::kG, 2},
};

const char* damping_name(DampingRule d) {
  switch (d) {
    case DampingRule::kRayleigh: return "rayleigh";
    case DampingRule::kModal: return "modal";
    default: return "stiffness";
  }
}

// Random numbers of one case: splitmix64 over (seed, index), uniform doubles
// from its top 53 bits (the same on every platform).
class Rng {
 public:
  Rng(std::uint64_t seed, std::int64_t index)
      : state_(seed * 0x9E3779B97F4A7C15ull ^ (static_cast<std::uint64_t>(index) + 1) * 0xD1B54A32D192ED03ull) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  int integer(int lo, int hi) { return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1)); }

 private:
  std::uint64_t state_;
};

// Lowest mode of a shear frame: omega^2 and effective mass, by inverse
// iteration with tridiagonal solves (any story count, no fixed-size Eigen).
struct FirstMode {
  double omega2 = 0, m_eff = 0;
};
FirstMode first_mode(const FrameParams& f) {
  const int n = f.stories;
  std::vector<double> x(n, 1.0), k(n + 1, 0.0), cp(n), dp(n);
  for (int i = 0; i < n; ++i) k[i] = story_stiffness(f, i);
  for (int it = 0; it < 100; ++it) {
    // Solve K y = M x (Thomas): diagonal k_i + k_{i+1}, off-diagonals -k_{i+1}.
    for (int i = 0; i < n; ++i) {
      const double b = k[i] + k[i + 1] - (i ? -k[i] * cp[i - 1] : 0.0);
      cp[i] = -k[i + 1] / b;
      dp[i] = (f.mass_kg[i] * x[i] - (i ? -k[i] * dp[i - 1] : 0.0)) / b;
    }
    for (int i = n - 1; i >= 0; --i) x[i] = dp[i] - (i + 1 < n ? cp[i] * x[i + 1] : 0.0);
    const double top = x[n - 1];
    for (double& v : x) v /= top;
  }
  double kx = 0, mx = 0, gamma = 0;
  for (int i = 0; i < n; ++i) {
    const double drift = x[i] - (i ? x[i - 1] : 0.0);
    kx += k[i] * drift * drift;
    mx += f.mass_kg[i] * x[i] * x[i];
    gamma += f.mass_kg[i] * x[i];
  }
  return {kx / mx, gamma * gamma / mx};
}

// A random shear frame of n stories: floor masses around m0 (10-1000 t,
// log-uniform), story stiffnesses tapering up the height, scaled so that f1
// is realistic for the height (10/n Hz times 0.4-2, log-uniform), and a
// damping rule with ratios of 0.5-5 %.
void draw_frame(Rng& rng, int n, FrameParams* f) {
  f->stories = n;
  const double m0 = rng.log_uniform(1e4, 1e6), taper = rng.uniform(0.3, 1.0);
  for (int i = 0; i < n; ++i) {
    f->mass_kg[i] = m0 * rng.uniform(0.6, 1.4);
    f->stiffness_n_per_m[i] = (1.0 - (1.0 - taper) * static_cast<double>(i) / std::max(n - 1, 1)) * rng.uniform(0.7, 1.3);
  }
  const double w1 = 2 * kPi * 10.0 / n * rng.log_uniform(0.4, 2.0);
  const double scale = w1 * w1 / first_mode(*f).omega2;
  for (int i = 0; i < n; ++i) f->stiffness_n_per_m[i] *= scale;
  // Rayleigh needs two modes; its two ratios are drawn independently.
  const int rule = rng.integer(0, n > 1 ? 2 : 1);
  f->damping = rule == 0 ? DampingRule::kStiffnessProportional : rule == 1 ? DampingRule::kModal : DampingRule::kRayleigh;
  f->stiffness_damping_s = 2.0 * rng.uniform(0.005, 0.05) / w1;
  f->modal_zeta = rng.uniform(0.005, 0.05);
  f->rayleigh_zeta[0] = rng.uniform(0.005, 0.05);
  f->rayleigh_zeta[1] = rng.uniform(0.005, 0.05);
  f->rayleigh_modes[0] = 1;
  f->rayleigh_modes[1] = rng.integer(2, std::max(2, std::min(n, 5)));
}

// A random VI NES: law, mass ratio 0.1-20 % (log-uniform), beta 1.01-3,
// eps 0.05-1, floor, and the particle anywhere in its free travel (one case
// in four against the left wall) moving at up to 1 m/s either way.
void draw_vines(Rng& rng, ContactLaw law, double m_eff1, DeviceParams* d, int stories) {
  d->kind = DeviceKind::kVines;
  d->floor = rng.integer(1, stories);
  d->mass_ratio = rng.log_uniform(0.001, 0.2);
  VinesParams& v = d->vines;
  v.law = law;
  v.beta = rng.uniform(1.01, 3.0);
  v.eps = rng.uniform(0.05, 1.0);
  const double radius = std::cbrt(3.0 * d->mass_ratio * m_eff1 / (4.0 * kPi * v.density_kg_m3));
  const double gap = (v.beta - 1.0) * radius;
  v.start_at_left_wall = rng.uniform(0.0, 1.0) < 0.25;
  v.initial_position_m = v.start_at_left_wall ? 0.0 : gap * rng.uniform(-1.0, 1.0) * (1.0 - 1e-9);
  v.initial_velocity_mps = rng.uniform(-1.0, 1.0);
}

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

}  // namespace

// ---- records ----
std::vector<StressRecord> load_stress_records() {
  std::vector<StressRecord> out;
  for (const RecordFile& f : kRecordFiles) {
    StressRecord r;
    r.file = f.file;
    r.spec.path = resolve_record_path(f.file, "");
    r.spec.format = f.format;
    r.spec.units = f.units;
    r.spec.column = f.column;
    r.record = hal::load_record(r.spec);
    out.push_back(std::move(r));
  }
  return out;
}

// ---- one case ----
StressCase draw_case(std::uint64_t seed, std::int64_t index, const std::vector<StressRecord>& records,
                     const StressLimits& limits) {
  Rng rng(seed, index);
  StressCase c;
  c.seed = seed;
  c.index = index;
  SceneParams& p = c.params;
  // The bare frame or a VI NES with one of the laws, equally likely; a frame
  // size among those compiled; float (where compiled) one case in four. A
  // law's code is its line in the registry's table (contact_laws.hpp).
  const int device = rng.integer(0, kContactLawCount);
  const DeviceKind kind = device == 0 ? DeviceKind::kNone : DeviceKind::kVines;
  const std::vector<int> frames = compiled_frames(Scalar::kDouble, kind);
  const int n = frames[static_cast<std::size_t>(rng.integer(0, static_cast<int>(frames.size()) - 1))];
  const std::vector<int> floats = compiled_frames(Scalar::kFloat, kind);
  const bool has_float = std::find(floats.begin(), floats.end(), n) != floats.end();
  if (rng.uniform(0.0, 1.0) < 0.25 && has_float) c.scalar = Scalar::kFloat;
  draw_frame(rng, n, &p.frame);
  if (kind == DeviceKind::kVines) draw_vines(rng, static_cast<ContactLaw>(device - 1), first_mode(p.frame).m_eff, &p.device, n);

  // Sensor 50 Hz-20 kHz (log-uniform). The stress looks for numerical trouble,
  // not for implausible buildings: the divergence guard is set far beyond any
  // displacement these records can cause, so that only a blow-up trips it.
  p.loop.sensor_rate_hz = rng.log_uniform(50.0, 20000.0);
  p.loop.divergence_limit_m = 1e6;
  p.loop.energy_ledger = true;  // the energy check reads the ledger
  if (kind == DeviceKind::kVines && rng.uniform(0.0, 1.0) < 0.125) c.small_cap = rng.integer(2, 8);

  // Record scaled 0.05-20x (log-uniform); a window of 2-6 s (shorter when the
  // sensor is fast: at most max_steps steps) that holds the record's PGA.
  c.record = rng.integer(0, static_cast<int>(records.size()) - 1);
  c.pga_scale = rng.log_uniform(0.05, 20.0);
  const hal::Record& rec = records[static_cast<std::size_t>(c.record)].record;
  const int size = static_cast<int>(rec.accel_mps2.size());
  const double window_s = std::min(rng.uniform(limits.min_window_s, limits.max_window_s),
                                   limits.max_steps / p.loop.sensor_rate_hz);
  c.window_samples = std::clamp(static_cast<int>(window_s / rec.dt_s) + 1, 2, size);
  const auto peak = std::max_element(rec.accel_mps2.begin(), rec.accel_mps2.end(),
                                     [](double a, double b) { return std::fabs(a) < std::fabs(b); });
  const int at = static_cast<int>(peak - rec.accel_mps2.begin());
  c.first_sample = rng.integer(std::max(0, at - c.window_samples + 1), std::min(at, size - c.window_samples));
  return c;
}

std::vector<double> case_samples(const StressCase& c, const std::vector<StressRecord>& records) {
  const hal::Record& rec = records[static_cast<std::size_t>(c.record)].record;
  hal::Record w;
  w.path = rec.path;
  w.dt_s = rec.dt_s;
  const auto first = rec.accel_mps2.begin() + c.first_sample;
  w.accel_mps2.assign(first, first + c.window_samples);
  for (double& a : w.accel_mps2) a *= c.pga_scale;
  return hal::resample(w, c.params.loop.sensor_rate_hz);
}

// ---- reporting ----
json case_json(const StressCase& c, const std::vector<StressRecord>& records) {
  const SceneParams& p = c.params;
  const hal::Record& rec = records[static_cast<std::size_t>(c.record)].record;
  const FirstMode fm = first_mode(p.frame);
  json j = {{"seed", c.seed},
            {"case", c.index},
            {"stories", p.frame.stories},
            {"device", p.device.kind == DeviceKind::kVines ? law_name(p.device.vines.law) : "none"},
            {"scalar", scalar_name(c.scalar)},
            {"sensor_rate_hz", p.loop.sensor_rate_hz},
            {"record", records[static_cast<std::size_t>(c.record)].file},
            {"pga_scale", c.pga_scale},
            {"window_start_s", c.first_sample * rec.dt_s},
            {"window_s", (c.window_samples - 1) * rec.dt_s},
            {"f1_hz", std::sqrt(fm.omega2) / (2 * kPi)},
            {"damping", damping_name(p.frame.damping)}};
  if (p.device.kind == DeviceKind::kVines) {
    const VinesParams& v = p.device.vines;
    j.update({{"floor", p.device.floor}, {"mass_ratio", p.device.mass_ratio}, {"beta", v.beta}, {"eps", v.eps},
              {"initial_position_m", v.start_at_left_wall ? json("left wall") : json(v.initial_position_m)},
              {"initial_velocity_mps", v.initial_velocity_mps}});
  }
  if (c.small_cap > 0) j["small_cap"] = c.small_cap;
  return j;
}

std::string write_case_scene(const StressCase& c, const std::vector<StressRecord>& records,
                             const std::string& dir) {
  const SceneParams& p = c.params;
  const FrameParams& f = p.frame;
  const double dt = records[static_cast<std::size_t>(c.record)].record.dt_s;
  const std::string stem = "case_" + std::to_string(c.index);
  create_folder(dir);
  // The window, scaled, one value a line in m/s^2 (17 digits: bit for bit).
  {
    std::string rec;
    const hal::Record& r = records[static_cast<std::size_t>(c.record)].record;
    for (int i = 0; i < c.window_samples; ++i) rec += num(r.accel_mps2[c.first_sample + i] * c.pga_scale) + '\n';
    write_file_atomic((fs::path(dir) / (stem + "_record.txt")).string(), rec);
  }
  // The scene as a toml++ table (doubles print in full: the same numbers back).
  auto list = [](const auto* v, int n) {
    toml::array a;
    for (int i = 0; i < n; ++i) a.push_back(v[i]);
    return a;
  };
  toml::table frame{{"preset", "custom"},
                    {"masses_kg", list(f.mass_kg, f.stories)},
                    {"stiffnesses_n_per_m", list(f.stiffness_n_per_m, f.stories)},
                    {"damping", damping_name(f.damping)},
                    {"stiffness_damping_s", f.stiffness_damping_s},
                    {"modal_zeta", f.modal_zeta}};
  if (f.stories > 1) {
    frame.insert("rayleigh_zeta", list(f.rayleigh_zeta, 2));
    frame.insert("rayleigh_modes", list(f.rayleigh_modes, 2));
  }
  toml::table scene{
      {"scene", toml::table{{"name", "stress_" + std::to_string(c.seed) + "_" + std::to_string(c.index)}}},
      {"frame", frame},
      {"record", toml::table{{"path", stem + "_record.txt"}, {"format", "accel"}, {"units", "m/s2"}, {"dt_s", dt}}},
      {"loop", toml::table{{"sensor_rate_hz", p.loop.sensor_rate_hz},
                           {"divergence_limit_m", p.loop.divergence_limit_m},
                           {"energy_ledger", true},
                           {"scalar", scalar_name(c.scalar)}}},
      {"output", toml::table{{"rate_hz", p.loop.sensor_rate_hz}}}};
  if (p.device.kind == DeviceKind::kVines) {
    const VinesParams& v = p.device.vines;
    scene.insert("device", toml::table{{"kind", "vines"}, {"floor", p.device.floor}, {"mass_ratio", p.device.mass_ratio}});
    toml::table vines{{"law", law_name(v.law)}, {"beta", v.beta}, {"eps", v.eps},
                      {"initial_velocity_mps", v.initial_velocity_mps}};
    if (!v.start_at_left_wall) vines.insert("initial_position_m", v.initial_position_m);
    scene.insert("vines", vines);
  }
  const fs::path path = fs::path(dir) / (stem + ".toml");
  std::ostringstream text;
  text << "# vines stress --seed " << c.seed << " --case " << c.index << "\n# " << case_json(c, records).dump()
       << "\n" << scene << '\n';
  write_file_atomic(path.string(), text.str());
  return path.string();
}

}  // namespace vines::host
