// Scene files (TOML, read with toml++). The format, in short (the full
// reference with examples is data/scenes/README.md):
//
//   [scene]   name                       (string, default: the file's stem)
//   [frame]   preset = "table1" | "sadek1997" | "custom"        (default table1)
//             masses_kg, stiffnesses_n_per_m   custom only, required there:
//                 equal-length arrays, bottom story first, 1..40 entries
//             damping = "stiffness" | "rayleigh" | "modal"   (default stiffness)
//             stiffness_damping_s, rayleigh_zeta = [z1, z2],
//             rayleigh_modes = [m1, m2], modal_zeta, stiffness_scale (eta_k),
//             stiffness_scales = [per story, bottom first]
//   [device]  kind = "none" | "tmd" | "vines"  (required when [device] is given;
//                 no [device] table means no device)
//             floor (1-based, default top), mass_ratio | mass_kg (not both)
//   [tmd]     k_n_per_m, c_ns_per_m (both absent: Den Hartog design),
//             initial_position_m, initial_velocity_mps
//   [vines]   radius_m, density_kg_m3, young_pa, poisson, wall_young_pa,
//             wall_poisson, beta | box_length_m (not both),
//             law = "kuwabara" | "tsuji" | "hertz" | "restitution" (the
//             laws of vines/model/contact_laws.hpp), eps,
//             v_ref_mps | tau_s (not both), initial_position_m,
//             initial_velocity_mps. Without initial_position_m the particle
//             starts against the left wall.
//   [record]  path (required), format = "auto" | "at2" | "time-accel" | "accel",
//             units = "g" | "m/s2" | "cm/s2", dt_s (format "accel" only, required
//             there), column (1-based, not with at2 / accel),
//             scale | pga_g (not both), duration_s
//   [loop]    sensor_rate_hz, contact_rtol, max_substeps_per_step,
//             contact_count_depth_m, energy_ledger (default false),
//             floor_peaks (default true), divergence_limit_m,
//             contact_scheme = "adaptive" | "bounded" | "split", bounded_substeps,
//             split_steps, scalar = "double" | "float" | "fixed",
//             fixed_accel_mps2, fixed_amplification, fixed_contact_speed_mps
//   [output]  rate_hz (must divide loop.sensor_rate_hz), timeseries, format (csv, npy)
//   [damage]  time_s, stiffness_scales (both required; damage.cpp)
//
// Rules:
// - Unknown tables and keys are errors; so is a value of the wrong type. An
//   integer is accepted where a real number is expected, never the reverse.
// - Every key present is type-checked. Values are range-checked where they
//   take effect (vines::validate for the physics, the checks below for the
//   host-only keys): a [tmd] table in a kind = "vines" scene, the Rayleigh keys
//   under damping = "stiffness", eps under law = "hertz" are read and ignored,
//   so one file can be flipped between alternatives by changing one word.
// - Keys whose 0 means "not given" in SceneParams (mass_kg, radius_m,
//   box_length_m, tau_s, k_n_per_m, c_ns_per_m) must be > 0 when written: to
//   get the default, leave the key out. Two keys that set the same thing
//   (mass_ratio/mass_kg, beta/box_length_m, v_ref_mps/tau_s, scale/pga_g, and
//   vines.radius_m with a device mass when kind = "vines") are refused together.
// - Messages: "FILE:LINE: table.key[index]: what is wrong" (LINE when known).
#include "sim_host/scene/scene.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "sim_host/scene/limits.hpp"
#include "sim_host/scene/names.hpp"
#include "sim_host/scene/section.hpp"
#include "sim_host/scene/table.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/frame_presets.hpp"
#include "vines/model/validate.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;
using namespace scene_detail;

// The contact laws a scene may name: the registry's (vines/model/contact_laws.hpp).
Choices<ContactLaw> law_choices() {
  Choices<ContactLaw> out;
  each_law([&](auto law) { out.emplace_back(decltype(law)::kName, decltype(law)::kTag); });
  return out;
}

// ---- [frame] ----
void read_frame(const Section& s, FrameParams* f) {
  enum class Preset { kTable1, kSadek1997, kCustom };
  Preset preset = Preset::kTable1;
  s.choose<Preset>(
      "preset",
      {{"table1", Preset::kTable1}, {"sadek1997", Preset::kSadek1997}, {"custom", Preset::kCustom}},
      &preset);
  apply_frame_preset(preset == Preset::kSadek1997 ? FramePreset::kSadek1997 : FramePreset::kTable1,
                     f);
  // Custom frames: both arrays, equal lengths, 1..kMaxStories stories.
  if (preset == Preset::kCustom) {
    std::vector<double> m, k;
    if (!s.read("masses_kg", &m)) s.fail_at("masses_kg", "required with preset = \"custom\"");
    if (!s.read("stiffnesses_n_per_m", &k))
      s.fail_at("stiffnesses_n_per_m", "required with preset = \"custom\"");
    if (m.empty() || m.size() > static_cast<std::size_t>(kMaxStories))
      s.fail_at("masses_kg", "must have 1 to " + std::to_string(kMaxStories) + " entries");
    if (k.size() != m.size())
      s.fail_at("stiffnesses_n_per_m",
                "must have as many entries as frame.masses_kg (" + std::to_string(m.size()) + ")");
    f->stories = static_cast<int>(m.size());
    std::copy(m.begin(), m.end(), f->mass_kg);
    std::copy(k.begin(), k.end(), f->stiffness_n_per_m);
  } else {
    for (const char* k : {"masses_kg", "stiffnesses_n_per_m"})
      if (s.has(k)) s.fail_at(k, "only with preset = \"custom\"");
  }
  // Damping rule and its parameters (those of the other rules are ignored).
  s.choose<DampingRule>("damping",
                        {{"stiffness", DampingRule::kStiffnessProportional},
                         {"rayleigh", DampingRule::kRayleigh},
                         {"modal", DampingRule::kModal}},
                        &f->damping);
  s.read("stiffness_damping_s", &f->stiffness_damping_s);
  s.read_fixed("rayleigh_zeta", f->rayleigh_zeta);
  s.read_fixed("rayleigh_modes", f->rayleigh_modes);
  s.read("modal_zeta", &f->modal_zeta);
  s.read("stiffness_scale", &f->stiffness_scale);
  // Per-story damage: one factor a story, bottom first.
  std::vector<double> scales;
  if (s.read("stiffness_scales", &scales)) {
    if (scales.size() != static_cast<std::size_t>(f->stories))
      s.fail_at("stiffness_scales", "must have one factor per story (" + std::to_string(f->stories) + ")");
    std::copy(scales.begin(), scales.end(), f->stiffness_scales);
  }
}

// ---- [device] ----
void read_device(const Section& s, DeviceParams* d) {
  if (!s.present()) return;  // no device
  if (!s.has("kind")) s.fail_at("kind", "required in [device] (\"none\", \"tmd\" or \"vines\")");
  s.choose<DeviceKind>(
      "kind",
      {{"none", DeviceKind::kNone}, {"tmd", DeviceKind::kTmd}, {"vines", DeviceKind::kVines}},
      &d->kind);
  if (s.read("floor", &d->floor) && d->floor < 1)
    s.fail_at("floor", "must be between 1 and the story count (leave it out for the top floor)");
  s.exclusive("mass_ratio", "mass_kg");
  s.read("mass_ratio", &d->mass_ratio);
  s.read_nonzero("mass_kg", &d->mass_kg);
}

// ---- [tmd] ----
void read_tmd(const Section& s, TmdParams* t) {
  s.read_nonzero("k_n_per_m", &t->k_n_per_m);
  s.read_nonzero("c_ns_per_m", &t->c_ns_per_m);
  s.read("initial_position_m", &t->initial_position_m);
  s.read("initial_velocity_mps", &t->initial_velocity_mps);
}

// ---- [vines] ----
void read_vines(const Section& s, VinesParams* v) {
  s.read_nonzero("radius_m", &v->radius_m);
  s.read("density_kg_m3", &v->density_kg_m3);
  s.read("young_pa", &v->young_pa);
  s.read("poisson", &v->poisson);
  s.read("wall_young_pa", &v->wall_young_pa);
  s.read("wall_poisson", &v->wall_poisson);
  s.exclusive("beta", "box_length_m");
  s.read("beta", &v->beta);
  s.read_nonzero("box_length_m", &v->box_length_m);
  s.choose<ContactLaw>("law", law_choices(), &v->law);
  s.read("eps", &v->eps);
  s.exclusive("v_ref_mps", "tau_s");
  s.read("v_ref_mps", &v->v_ref_mps);
  s.read_nonzero("tau_s", &v->tau_s);
  v->start_at_left_wall = !s.read("initial_position_m", &v->initial_position_m);
  s.read("initial_velocity_mps", &v->initial_velocity_mps);
}

// ---- [record] (host only: checked here) ----
void read_record(const Section& s, Scene* scene) {
  hal::RecordSpec& r = scene->record;
  if (!s.read("path", &r.path) || r.path.empty())
    s.fail_at("path", "required: the ground-motion record file");
  s.choose<hal::RecordFormat>("format", kRecordFormats, &r.format);
  s.choose<hal::Units>("units", kRecordUnits, &r.units);
  const bool accel = r.format == hal::RecordFormat::kAccel;
  if (s.read("dt_s", &r.dt_s)) {
    if (!accel) s.fail_at("dt_s", "only with format = \"accel\" (other formats carry their own)");
    if (!(std::isfinite(r.dt_s) && r.dt_s > 0.0)) s.fail_at("dt_s", "must be finite and > 0");
  } else if (accel) {
    s.fail_at("dt_s", "required with format = \"accel\"");
  }
  if (s.read("column", &r.column)) {
    if (accel || r.format == hal::RecordFormat::kAt2)
      s.fail_at("column", "only with format = \"time-accel\" or \"auto\"");
    if (r.column < 1) s.fail_at("column", "must be >= 1 (1 = first column after time)");
  }
  s.exclusive("scale", "pga_g");
  if (s.read("scale", &r.scale) && !(std::isfinite(r.scale) && r.scale != 0.0))
    s.fail_at("scale", "must be finite and non-zero");
  double pga_g = 0.0;
  if (s.read("pga_g", &pga_g)) {
    if (!(std::isfinite(pga_g) && pga_g > 0.0 && pga_g <= 10.0))
      s.fail_at("pga_g", "must be in (0, 10]");
    scene->target_pga_mps2 = pga_g * kGravity;
  }
  if (s.read("duration_s", &scene->duration_s) &&
      !(std::isfinite(scene->duration_s) && scene->duration_s > 0.0))
    s.fail_at("duration_s", "must be finite and > 0 (leave it out for the whole record)");
}

// ---- [loop] ----
void read_loop(const Section& s, LoopParams* l, FixedParams* f, Scalar* scalar) {
  s.read("sensor_rate_hz", &l->sensor_rate_hz);
  s.read("contact_rtol", &l->contact_rtol);
  s.read("max_substeps_per_step", &l->max_substeps_per_step);
  s.read("contact_count_depth_m", &l->contact_count_depth_m);
  s.read("energy_ledger", &l->energy_ledger);
  s.read("floor_peaks", &l->floor_peaks);
  s.read("divergence_limit_m", &l->divergence_limit_m);
  s.choose<ContactScheme>("contact_scheme",
                          {{"adaptive", ContactScheme::kAdaptive},
                           {"bounded", ContactScheme::kBounded},
                           {"split", ContactScheme::kSplit}},
                          &l->contact_scheme);
  s.read("bounded_substeps", &l->bounded_substeps);
  s.read("split_steps", &l->split_steps);
  s.read("fixed_accel_mps2", &f->accel_mps2);
  s.read("fixed_amplification", &f->amplification);
  s.read("fixed_contact_speed_mps", &f->contact_speed_mps);
  s.choose<Scalar>("scalar", {{"double", Scalar::kDouble}, {"float", Scalar::kFloat}, {"fixed", Scalar::kFixed}},
                   scalar);
}

// ---- [output] (host only; needs a validated sensor rate) ----
void read_output(const Section& s, double sensor_rate_hz, OutputSpec* o) {
  s.read("timeseries", &o->timeseries);
  s.choose<TimeseriesFormat>("format", {{"csv", TimeseriesFormat::kCsv}, {"npy", TimeseriesFormat::kNpy}}, &o->format);
  const std::string which = s.read("rate_hz", &o->rate_hz) ? "" : " (the default)";
  std::ostringstream sensor;
  sensor << "loop.sensor_rate_hz = " << sensor_rate_hz;
  if (!(std::isfinite(o->rate_hz) && o->rate_hz > 0.0 && o->rate_hz <= sensor_rate_hz))
    s.fail_at("rate_hz", o->rate_hz > 0.0 ? "must not exceed " + sensor.str() + which
                                          : "must be finite and > 0");
  const double ratio = sensor_rate_hz / o->rate_hz;
  if (std::fabs(ratio - std::round(ratio)) > 1e-9 * ratio)
    s.fail_at("rate_hz", "must divide " + sensor.str() + " (a row every k-th sample)" + which);
}

// ParamError field names that differ from the scene keys.
std::string scene_key(const ParamError& e) {
  const std::string_view f = e.field;
  if (f == "frame.masses" || f == "frame.stories") return "frame.masses_kg";
  if (f == "frame.stiffnesses") return "frame.stiffnesses_n_per_m";
  return std::string(f);
}

}  // namespace

// ---- parse: TOML text -> table ----
toml::table parse_scene_table(const std::string& toml_text, const std::string& origin) {
  try {
    return toml::parse(toml_text, origin);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw SceneError(origin + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
}

Scene parse_scene(const std::string& toml_text, const std::string& origin) {
  return scene_from_table(parse_scene_table(toml_text, origin), origin);
}

// ---- the format: each table's keys ----
namespace {
const std::initializer_list<std::string_view> kTables = {"scene", "frame",  "device", "tmd",
                                                         "vines", "record", "loop",   "output", "damage"};
const std::initializer_list<std::string_view> kSceneKeys = {"name"};
const std::initializer_list<std::string_view> kFrameKeys = {
    "preset", "masses_kg", "stiffnesses_n_per_m", "damping", "stiffness_damping_s", "rayleigh_zeta",
    "rayleigh_modes", "modal_zeta", "stiffness_scale", "stiffness_scales"};
const std::initializer_list<std::string_view> kDeviceKeys = {"kind", "floor", "mass_ratio", "mass_kg"};
const std::initializer_list<std::string_view> kTmdKeys = {"k_n_per_m", "c_ns_per_m", "initial_position_m",
                                                          "initial_velocity_mps"};
const std::initializer_list<std::string_view> kVinesKeys = {
    "radius_m", "density_kg_m3", "young_pa", "poisson", "wall_young_pa", "wall_poisson", "beta",
    "box_length_m", "law", "eps", "v_ref_mps", "tau_s", "initial_position_m", "initial_velocity_mps"};
const std::initializer_list<std::string_view> kRecordKeys = {"path",   "format", "units",   "dt_s",
                                                             "column", "scale",  "pga_g", "duration_s"};
const std::initializer_list<std::string_view> kLoopKeys = {
    "sensor_rate_hz", "contact_rtol",   "max_substeps_per_step", "contact_count_depth_m", "energy_ledger",
    "floor_peaks",    "divergence_limit_m", "contact_scheme",    "bounded_substeps",      "split_steps",
    "scalar",         "fixed_accel_mps2",   "fixed_amplification", "fixed_contact_speed_mps"};
const std::initializer_list<std::string_view> kOutputKeys = {"rate_hz", "timeseries", "format"};
const std::initializer_list<std::string_view> kDamageKeys = {"time_s", "stiffness_scales"};
}  // namespace

bool is_scene_key(const std::string& dotted) {
  const std::size_t dot = dotted.find('.');
  if (dot == std::string::npos) return false;
  const std::string_view table(dotted.data(), dot), key(dotted.data() + dot + 1, dotted.size() - dot - 1);
  for (const auto& [name, keys] : {std::pair{"scene", kSceneKeys}, {"frame", kFrameKeys}, {"device", kDeviceKeys},
                                   {"tmd", kTmdKeys}, {"vines", kVinesKeys}, {"record", kRecordKeys},
                                   {"loop", kLoopKeys}, {"output", kOutputKeys},
                                   {"damage", kDamageKeys}})
    if (table == name) return std::find(keys.begin(), keys.end(), key) != keys.end();
  return false;
}

// ---- table -> checked Scene ----
Scene scene_from_table(const toml::table& root, const std::string& origin) {
  // Top level: only the known tables.
  for (auto&& kv : root)
    if (std::find(kTables.begin(), kTables.end(), kv.first.str()) == kTables.end())
      fail(origin, &kv.first.source(), std::string(kv.first.str()),
           "unknown table (known: " + join(kTables) + ")");

  Scene scene;
  scene.path = origin;
  scene.name = fs::path(origin).stem().string();
  SceneParams& p = scene.params;
  p.loop.floor_peaks = true;  // a scene's run reports every floor unless told not to

  const Section meta(origin, root, "scene", kSceneKeys);
  if (meta.read("name", &scene.name) && scene.name.empty())
    meta.fail_at("name", "must not be empty");
  read_frame(Section(origin, root, "frame", kFrameKeys), &p.frame);
  const Section device(origin, root, "device", kDeviceKeys);
  read_device(device, &p.device);
  read_tmd(Section(origin, root, "tmd", kTmdKeys), &p.device.tmd);
  const Section vines(origin, root, "vines", kVinesKeys);
  read_vines(vines, &p.device.vines);
  // The sphere's radius sets its mass: a device mass as well is a conflict.
  if (p.device.kind == DeviceKind::kVines && vines.has("radius_m") &&
      (device.has("mass_ratio") || device.has("mass_kg")))
    vines.fail_at("radius_m", "sets the particle mass; conflicts with device.mass_ratio / mass_kg");

  const Section record(origin, root, "record", kRecordKeys);
  if (!record.present())
    fail(origin, nullptr, "record", "missing table: the scene needs a [record]");
  read_record(record, &scene);
  read_loop(Section(origin, root, "loop", kLoopKeys), &p.loop, &p.fixed, &scene.scalar);

  // The shared range checks, reported at the offending key's line.
  if (const ParamError e = validate(p); !e.ok()) {
    std::string key = scene_key(e);
    if (e.index >= 0) key += "[" + std::to_string(e.index) + "]";
    const toml::node* n = root.at_path(key).node();
    fail(origin, n != nullptr ? &n->source() : nullptr, key, e.message);
  }
  // Contact scales no run could resolve, or overlaps past the sphere (scene_limits.hpp).
  if (const auto e = check_contact_scales(p)) {
    const toml::node* n = root.at_path(e->key).node();
    fail(origin, n != nullptr ? &n->source() : nullptr, e->key, e->message);
  }
  read_output(Section(origin, root, "output", kOutputKeys), p.loop.sensor_rate_hz,
              &scene.output);
  read_damage(Section(origin, root, "damage", kDamageKeys), p.frame.stories, &scene.damage);
  return scene;
}

// ---- load: file -> table -> Scene ----
toml::table read_scene_table(const std::string& path) {
  std::string text;
  try {
    text = hal::read_input_file(path, kMaxSceneBytes);
  } catch (const std::runtime_error& e) {
    throw SceneError(std::string(e.what()) + " (a scene file)");
  }
  return parse_scene_table(text, path);
}

Scene load_scene(const std::string& path) { return scene_from_table(read_scene_table(path), path); }

}  // namespace vines::host
