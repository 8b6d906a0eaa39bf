// `vines run SCENE.toml`: one scene (and its bare frame), summary.json and timeseries.csv.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/names.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::cli {
namespace {

// --record-format and --record-units take the scene's [record] names
// (host::kRecordFormats, host::kRecordUnits), listed in sorted order.
template <class E>
std::vector<std::string> names_of(const host::NamedValues<E>& values) {
  std::vector<std::string> out;
  for (const auto& kv : values) out.emplace_back(kv.first);
  std::sort(out.begin(), out.end());
  return out;
}

struct RunArgs {
  std::string scene_path;
  std::string record_format = "auto", record_units = "g";
  host::RunOptions opt;
  const CLI::Option* out = nullptr;  // --out, given or not
  const CLI::App* cmd = nullptr;     // the options given (check_reading)
  bool accept_degraded = false;
  std::string format;  // --format: "" the scene's [output] format
};

// How to read the --record file: an option the file's format does not take
// is a usage error, not ignored (an AT2 header gives its time step and units,
// only a time/accel file has columns to pick, only values need a step).
void check_reading(const RunArgs& a) {
  const std::string& path = a.opt.record_override;
  const bool dt = a.cmd->count("--record-dt") > 0, units = a.cmd->count("--record-units") > 0,
             column = a.cmd->count("--record-column") > 0;
  if (path.empty() || !(dt || units || column)) return;
  hal::RecordFormat f = a.opt.record_reading.format;
  if (f == hal::RecordFormat::kAuto) f = hal::detect_record_format(path);
  std::string name;
  for (const auto& [n, v] : host::kRecordFormats)
    if (v == f) name = n;
  const std::string read_as = path + " is read as " + name;
  if (dt && f != hal::RecordFormat::kAccel)
    throw CLI::ValidationError("--record-dt", read_as + ": its time step comes from the file");
  if (units && f == hal::RecordFormat::kAt2)
    throw CLI::ValidationError("--record-units", read_as + ": its header gives its units");
  if (column && f != hal::RecordFormat::kTimeAccel)
    throw CLI::ValidationError("--record-column", read_as + ": only a time/accel file has columns to pick");
}

int run(RunArgs a) {
  using namespace vines::host;
  RunOptions& opt = a.opt;
  opt.record_reading.format = *host::named(host::kRecordFormats, a.record_format);  // checked by CLI11
  opt.record_reading.units = *host::named(host::kRecordUnits, a.record_units);
  check_reading(a);
  Scene scene = load_scene(a.scene_path);
  if (!a.format.empty())
    scene.output.format = a.format == "npy" ? host::TimeseriesFormat::kNpy : host::TimeseriesFormat::kCsv;
  if (a.out->count() == 0) opt.out_dir = "out/" + safe_file_name(scene.name);
  const RunReport r = run_scene(scene, opt);
  const vines::SceneParams& p = scene.params;
  const Counters& k = r.totals.count;
  if (!opt.quiet) {
    std::printf("scene %s: %s, %d stories, %s, %.0f Hz\n", scene.name.c_str(), device_name(p.device.kind),
                r.info.stories, scalar_name(r.scalar), p.loop.sensor_rate_hz);
    if (r.damage.present()) {
      std::string scales;
      char one[64];
      for (std::size_t i = 0; i < r.damage.stiffness_scales.size(); ++i)
        if (r.damage.stiffness_scales[i] != 1.0) {
          std::snprintf(one, sizeof one, "%sstory %zu x %g", scales.empty() ? "" : ", ", i + 1,
                        r.damage.stiffness_scales[i]);
          scales += one;
        }
      std::printf("  damage at t = %.3f s: %s\n", r.damage_switch_s,
                  scales.empty() ? "every factor 1 (no change)" : scales.c_str());
    }
    std::printf("  peak top displacement %.6f m at t = %.3f s\n", r.totals.peak_top, r.totals.t_peak_top);
    if (r.bare)
      std::printf("  x_r = %.2f %%   E_r = %.2f %%   (bare peak %.6f m)\n", 100 * r.x_r(), 100 * r.E_r(),
                  r.bare->peak_top);
    if (p.device.kind == vines::DeviceKind::kVines)
      std::printf("  contacts %lld, deepest overlap %.3f mm, contact sub-steps %lld\n",
                  static_cast<long long>(k.contacts), 1e3 * r.totals.max_overlap,
                  static_cast<long long>(k.contact_substeps));
    if (p.loop.energy_ledger)
      std::printf("  energy balance residual %.2e (relative)\n", r.totals.ledger.relative_residual());
    else
      std::printf("  energy balance not computed (loop.energy_ledger = false)\n");
    std::printf("  loop wall time %.2f ms; results in %s/\n", 1e3 * r.wall_s, opt.out_dir.c_str());
    if (r.status.ok()) std::printf("  status: ok\n");
  }
  // A degraded result is reported with its reasons, never silent (even with --quiet).
  if (!r.status.ok()) {
    std::fflush(stdout);  // after the summary, when both go to one place
    std::fprintf(stderr, "vines run: status: DEGRADED\n");
    for (const StatusReason& why : r.status.reasons)
      std::fprintf(stderr, "  %s: %s\n", why.code.c_str(), why.message.c_str());
  }
  return finished_status(!r.status.ok(), a.accept_degraded);
}

}  // namespace

void add_run(CLI::App& vines) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* cmd = add_command(vines, "run",
                              "Run a scene (frame, device, contact law, record). With a device, the bare frame runs "
                              "on the same record too and x_r, E_r are reported. Writes DIR/summary.json and "
                              "DIR/timeseries.csv (or .npy).",
                              "", [a] { return run(*a); });
  a->cmd = cmd;
  cmd->add_option("SCENE.toml", a->scene_path, "scene file (see data/scenes/README.md)")->required();
  cmd->add_option("--record", a->opt.record_override,
                  "use this ground-motion file instead of the scene's [record] path; its format is read from "
                  "the file (a PEER AT2 header, else time/accel columns, or one column of values); of the "
                  "scene's [record], only scale / pga_g and duration_s apply to it")
      ->type_name("PATH");
  // How to read the --record file (the names of the scene's [record] format and units).
  auto* rec = cmd->get_option("--record");
  cmd->add_option("--record-format", a->record_format, "force the --record file's format: auto (default), at2, "
                                                       "time-accel or accel (values only, needs --record-dt)")
      ->type_name("FORMAT")->check(CLI::IsMember(names_of(host::kRecordFormats)))->needs(rec);
  cmd->add_option("--record-units", a->record_units, "units of a --record columns file: g (default), m/s2 or "
                                                     "cm/s2 (an AT2 file's header says its own)")
      ->type_name("UNITS")->check(CLI::IsMember(names_of(host::kRecordUnits)))->needs(rec);
  host::RecordReading& how = a->opt.record_reading;
  cmd->add_option("--record-column", how.column, "acceleration column of a --record time/accel file "
                                                 "(1, the default, = the first after the time)")
      ->type_name("N")->check(number_in(1, 1000))->needs(rec);
  cmd->add_option("--record-dt", how.dt_s, "sample step of a --record file of values only [s]")
      ->type_name("SECONDS")->check(positive_up_to(hal::kMaxRecordDt))->needs(rec);
  a->out = cmd->add_option("--out", a->opt.out_dir,
                           "output folder: new, empty or vines run's own; its files this run does not write are "
                           "removed (default: out/<scene name>)")
               ->type_name("DIR")
               ->check(non_empty_path());
  cmd->add_option("--format", a->format,
                  "timeseries format: csv (text, each number in its shortest exact form) or npy (NumPy, the "
                  "values' bytes; numpy.load reads it); both read back bit for bit (default: the scene's "
                  "[output] format, else csv)")
      ->type_name("FORMAT")
      ->check(CLI::IsMember({"csv", "npy"}));
  cmd->add_flag("--quiet", a->opt.quiet, "print nothing but errors and a degraded status");
  add_accept_degraded(*cmd, &a->accept_degraded);
}

}  // namespace vines::cli
