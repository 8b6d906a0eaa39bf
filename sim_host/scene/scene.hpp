// Scene files: TOML descriptions of a run (frame, device, contact law, record,
// loop settings, outputs), turned into SceneParams for the firmware core and a
// RecordSpec for the host HAL. Every problem is a SceneError whose message
// names the file and the key ("scene.toml: vines.beta: must be > 1 ...").
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/record.hpp"
#include "sim_host/scene/scalar.hpp"
#include "vines/model/params.hpp"

namespace vines::host {

// timeseries.csv (text, every number in its shortest exact form) or
// timeseries.npy (NumPy, the values' bytes): the same columns and values.
enum class TimeseriesFormat { kCsv, kNpy };

struct OutputSpec {
  double rate_hz = 100.0;  // timeseries rows per second of record (<= sensor rate)
  bool timeseries = true;
  TimeseriesFormat format = TimeseriesFormat::kCsv;
};

// [damage]: damage that strikes during the earthquake. Until time_s the frame
// is the scene's; from the sample at time_s on, story i's stiffness (and with
// stiffness-proportional damping its damping) is multiplied by
// stiffness_scales[i] as well (bottom first, each in (0, 1]).
struct DamageSpec {
  double time_s = 0;                     // seconds from the record's start
  std::vector<double> stiffness_scales;  // one per story; empty: no [damage]
  bool present() const { return !stiffness_scales.empty(); }
  // Whether some story loses stiffness (every factor 1: a no-op).
  bool any() const {
    for (double s : stiffness_scales)
      if (s != 1.0) return true;
    return false;
  }
};

struct Scene {
  std::string path;       // the scene file
  std::string name;       // [scene] name, default: file stem
  SceneParams params;
  hal::RecordSpec record;  // path resolved by resolve_record_path()
  double duration_s = 0.0; // 0: the whole record
  // 0: the record as loaded (times record.scale); > 0: the loader rescales
  // the record so that its PGA is this value ([record] pga_g).
  double target_pga_mps2 = 0.0;
  Scalar scalar = Scalar::kDouble;
  OutputSpec output;
  DamageSpec damage;
};

// Scene files and study specs are at most 1 MiB: the largest shipped is 3 kB,
// and a custom frame of 40 stories with every key written fits in 10 kB.
inline constexpr std::uintmax_t kMaxSceneBytes = 1u << 20;

class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses and validates a scene file (not a regular file, over kMaxSceneBytes,
// unknown keys, wrong types, bad values are SceneErrors). The record path is left as written; see resolve_record_path.
Scene load_scene(const std::string& path);

// Whether "table.key" is a key of the scene format (a sweep's keys are
// checked at load: a typo fails the spec, not every run).
bool is_scene_key(const std::string& dotted);

// Same, from TOML text (for tests); `origin` names it in messages.
Scene parse_scene(const std::string& toml_text, const std::string& origin);

// Finds a record file: an absolute path as is; a relative one is tried against
// the working directory, the scene file's folder, then the ground-motion folder
// ($VINES_GROUND_MOTIONS, else ../shared/data/ground_motions beside the
// repository). Throws SceneError listing the places tried.
std::string resolve_record_path(const std::string& record_path, const std::string& scene_path);

// Parameters `p` (the scene's, or its bare frame's) after the damage
// strikes: each story's frame.stiffness_scales times the damage's (p itself
// without [damage]). The devices are designed on the undamaged frame, so
// they stay the same.
SceneParams damaged_params(SceneParams p, const DamageSpec& damage);

// Refuses (SceneError naming the scene, damage.time_s, the time and the
// record's length) a [damage] whose time_s is not inside the record as run:
// `record_s` the seconds simulated (the record, or duration_s when set).
// `who` names the scene in the message ("" : its path).
void check_damage_time(const Scene& scene, double record_s, const std::string& who = "");

// Refuses (SceneError) a scene with [damage] where a command does not run it
// (`command`, e.g. "vines sweep"): vines run and the twin's truth do.
void refuse_damage(const Scene& scene, const std::string& command);

}  // namespace vines::host
