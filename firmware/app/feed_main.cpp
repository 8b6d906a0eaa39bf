// vines_feed: the host end of the sample link. Loads a scene and its record
// exactly as `vines run` does (same resampling to the sensor rate), writes
// the byte stream the firmware loop reads (vines/hal/link_protocol.hpp), and
// writes the host's own summary of the same run (run_scene, the code behind
// `vines run`) for comparison.
//   vines_feed SCENE.toml --scalar float|double --feed OUT.bin
//              [--summary OUT.json] [--budget-ticks N] [--duration S]
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>

#include "sim_host/run.hpp"
#include "sim_host/scene.hpp"
#include "vines/hal/link_protocol.hpp"

namespace {

constexpr const char* kUsage =
    "usage: vines_feed SCENE.toml --scalar float|double --feed OUT.bin [--summary OUT.json]\n"
    "                  [--budget-ticks N] [--duration S]\n"
    "  --feed FILE       the stream for the firmware loop's link (header, scene, samples)\n"
    "  --summary FILE    the host run of the same scene and scalar (JSON, as vines run)\n"
    "  --budget-ticks N  deadline per step in the loop's counter ticks (default: one period)\n"
    "  --duration S      only the first S seconds of the record\n";

int usage(const std::string& what) {
  std::fprintf(stderr, "vines_feed: %s\n\n%s", what.c_str(), kUsage);
  return 2;
}

template <typename T>
void put(std::ofstream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_path, feed_path, summary_path, scalar;
  unsigned long budget = 0;
  double duration = 0.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    const bool takes_value = a == "--scalar" || a == "--feed" || a == "--summary" || a == "--budget-ticks" ||
                             a == "--duration";
    if (takes_value && i + 1 >= argc) return usage(a + " needs a value");
    try {
      if (a == "--scalar") scalar = argv[++i];
      else if (a == "--feed") feed_path = argv[++i];
      else if (a == "--summary") summary_path = argv[++i];
      else if (a == "--budget-ticks") budget = std::stoul(argv[++i]);
      else if (a == "--duration") duration = std::stod(argv[++i]);
      else if (!a.empty() && a[0] == '-') return usage("unknown option " + a);
      else if (scene_path.empty()) scene_path = a;
      else return usage("more than one scene given");
    } catch (const std::exception&) {
      return usage("bad value for " + a + ": " + argv[i]);
    }
  }
  if (scene_path.empty()) return usage("no scene given");
  if (scalar != "float" && scalar != "double") return usage("--scalar must be float or double");
  if (feed_path.empty()) return usage("--feed is required");
  if (budget > 0xFFFFFFFFul) return usage("--budget-ticks: too large");
  if (!(duration >= 0.0)) return usage("--duration must be >= 0");
  try {
    vines::host::Scene scene = vines::host::load_scene(scene_path);
    scene.scalar = scalar == "float" ? vines::host::Scalar::kFloat : vines::host::Scalar::kDouble;
    if (duration > 0.0) scene.duration_s = duration;
    const vines::host::Excitation ex = vines::host::load_excitation(scene, "");
    if (ex.samples.size() > 0xFFFFFFFFu) throw std::runtime_error(scene_path + ": record too long for the link");

    std::ofstream feed(feed_path, std::ios::binary);
    if (!feed) throw std::runtime_error(feed_path + ": cannot write");
    vines::hal::link::Header h{};
    std::memcpy(h.magic, vines::hal::link::kMagic, 4);
    h.params_bytes = sizeof(vines::SceneParams);
    h.params_layout = vines::hal::link::layout_check();
    h.sample_bytes = scalar == "float" ? 4 : 8;
    h.samples = static_cast<std::uint32_t>(ex.samples.size());
    h.budget_ticks = static_cast<std::uint32_t>(budget);
    put(feed, h);
    put(feed, scene.params);
    for (const double a : ex.samples) {
      if (scalar == "float") put(feed, static_cast<float>(a));  // what the host's float engine sees
      else put(feed, a);
    }
    if (!feed.flush()) throw std::runtime_error(feed_path + ": write failed");

    if (!summary_path.empty()) {
      const nlohmann::json j = vines::host::run_scene(scene, vines::host::RunOptions{});
      std::ofstream out(summary_path);
      if (!(out << j.dump(2) << '\n')) throw std::runtime_error(summary_path + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vines_feed: %s\n", e.what());
    return 1;
  }
  return 0;
}
