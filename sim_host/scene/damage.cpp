// [damage]: damage that strikes during the earthquake (scene.hpp, DamageSpec).
// Read here, its time checked against the record where the record is known
// (vines run, the twin's truth).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "sim_host/scene/scene.hpp"
#include "sim_host/scene/section.hpp"

namespace vines::host {
namespace scene_detail {

void read_damage(const Section& s, int stories, DamageSpec* d) {
  if (!s.present()) return;
  if (!s.read("time_s", &d->time_s)) s.fail_at("time_s", "required in [damage] (when the damage strikes, in seconds)");
  if (!(std::isfinite(d->time_s) && d->time_s >= 0.0))
    s.fail_at("time_s", "must be finite and >= 0 (seconds from the record's start)");
  std::vector<double> scales;
  if (!s.read("stiffness_scales", &scales))
    s.fail_at("stiffness_scales", "required in [damage] (one factor per story, bottom first)");
  if (scales.size() != static_cast<std::size_t>(stories))
    s.fail_at("stiffness_scales", "must have one factor per story (" + std::to_string(stories) + ", got " +
                                      std::to_string(scales.size()) + ")");
  for (std::size_t i = 0; i < scales.size(); ++i) {
    const double f = scales[i];
    if (!(std::isfinite(f) && f > 0.0)) s.fail_at("stiffness_scales", "must be finite and > 0", static_cast<int>(i));
    if (f > 1.0)
      s.fail_at("stiffness_scales", "a factor above 1 is not damage (each in (0, 1])", static_cast<int>(i));
  }
  d->stiffness_scales = std::move(scales);
}

}  // namespace scene_detail

SceneParams damaged_params(SceneParams p, const DamageSpec& damage) {
  const std::vector<double>& s = damage.stiffness_scales;
  for (std::size_t i = 0; i < s.size() && i < static_cast<std::size_t>(kMaxStories); ++i)
    p.frame.stiffness_scales[i] *= s[i];
  return p;
}

void check_damage_time(const Scene& scene, double record_s, const std::string& who) {
  if (!scene.damage.present() || scene.damage.time_s < record_s) return;
  std::ostringstream os;
  os << (who.empty() ? scene.path : who) << ": damage.time_s: " << scene.damage.time_s
     << " s is not inside the record as run (" << record_s << " s"
     << (scene.duration_s > 0.0 ? ", record.duration_s" : "") << "): the damage would never strike";
  throw SceneError(os.str());
}

void refuse_damage(const Scene& scene, const std::string& command) {
  if (!scene.damage.present()) return;
  throw SceneError(scene.path + ": [damage]: " + command +
                   " does not run damage that strikes mid-record (vines run and the twin's --truth do); "
                   "leave the table out, or give the damaged frame as frame.stiffness_scales");
}

}  // namespace vines::host
