// A model image written by the host program (`vines image`, modal vectors
// padded to the host's VINES_MODAL_LANES) loads into a build that does not
// pad (VINES_MODAL_LANES=1, as on the MCU): this program is compiled that way
// and must not link anything built with the host's padding (vines_core,
// vines_host). For each scene and scalar it loads the image in 1-byte and
// 256-byte chunks, writes the loaded model back (the same bytes), builds the
// scene's model itself (mirrored SceneParams) and steps both over the first
// 5 s of El Centro: the same steps bit for bit (state, particle, E_e, peak,
// counters).
// usage: model_image_lanes1 VINES_EXE SCENES_DIR RECORD.dat WORKDIR
// Exit status 0 when every check holds.
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "vines/build/build_model.hpp"
#include "vines/image/model_image.hpp"
#include "vines/model/frame_presets.hpp"
#include "vines/step/sim.hpp"

static_assert(VINES_MODAL_LANES == 1, "this check is the unpadded build");

namespace {

using namespace vines;
using Bytes = std::vector<std::uint8_t>;
int g_failures = 0;

void fail(const std::string& what) {
  std::fprintf(stderr, "model_image_lanes1: FAIL: %s\n", what.c_str());
  ++g_failures;
}

Bytes read_file(const std::string& path) {
  Bytes b;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return b;
  std::uint8_t buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) b.insert(b.end(), buf, buf + n);
  std::fclose(f);
  return b;
}

// El Centro (time [s], acceleration [g]; dt 0.02 s), linear to 1 kHz, 5 s.
std::vector<double> record_head(const std::string& path) {
  std::vector<double> knots;
  std::FILE* f = std::fopen(path.c_str(), "r");
  double t, a;
  while (f && std::fscanf(f, "%lf %lf", &t, &a) == 2) knots.push_back(a * kGravity);
  if (f) std::fclose(f);
  std::vector<double> out;
  for (int k = 0; k <= 5000 && !knots.empty(); ++k) {
    const double u = k / 20.0;  // knot units
    const std::size_t i = static_cast<std::size_t>(u);
    const double w = u - static_cast<double>(i);
    out.push_back(i + 1 < knots.size() ? (1 - w) * knots[i] + w * knots[i + 1] : knots.back());
  }
  return out;
}

// The scenes' SceneParams (data/scenes/elcentro_*.toml), as the host reads them.
SceneParams scene_params(DeviceKind kind, ContactLaw law) {
  SceneParams p;
  apply_frame_preset(FramePreset::kTable1, &p.frame);
  p.device.kind = kind;
  p.device.mass_ratio = 0.05;
  p.device.vines.law = law;
  p.device.vines.beta = 1.35;
  p.device.vines.eps = 0.7;
  p.device.vines.v_ref_mps = 0.5;
  p.loop.energy_ledger = true;
  p.loop.floor_peaks = true;  // a scene's default
  p.loop.sensor_rate_hz = 1000.0;
  return p;
}

template <typename S, typename Dev>
void check(const std::string& exe, const std::string& scenes, const std::string& work, const char* scene,
           const std::vector<double>& rec) {
  using M = Model<S, 10, Dev>;
  using D = Data<S, 10, Dev>;
  const char* scalar = sizeof(S) == 4 ? "float" : "double";
  const std::string tag = std::string(scene) + " " + scalar;
  const std::string file = work + "/" + scene + "_" + scalar + ".img";
  const std::string cmd = exe + " image " + scenes + "/" + scene + ".toml --scalar " + scalar + " --out " + file +
                          " > /dev/null";
  if (std::system(cmd.c_str()) != 0) return fail(tag + ": `" + cmd + "` failed");
  const Bytes img = read_file(file);
  if (img.size() != image::image_bytes<S, 10, Dev>()) return fail(tag + ": image size differs");

  // Heap blocks (static storage is the firmware's way; a test may use the heap).
  auto loaded = std::make_unique<M>(), own = std::make_unique<M>();
  image::Loader<S, 10, Dev> ld(loaded.get());
  for (std::size_t chunk : {std::size_t{1}, std::size_t{256}}) {
    ld.reset();
    const char* why = nullptr;
    for (std::size_t i = 0; i < img.size() && !why; i += chunk)
      why = ld.push(img.data() + i, img.size() - i < chunk ? img.size() - i : chunk);
    if (!why) why = ld.finish();
    if (why || !ld.ready()) return fail(tag + ": refused: " + (why ? why : "not ready"));
  }
  Bytes back(img.size());
  if (image::write_image(*loaded, back.data(), back.size()) != img.size() || back != img)
    fail(tag + ": the loaded model does not write the same image");

  const ParamError e = build_model(scene_params(Dev::kKind, [] {
                                     if constexpr (Dev::kKind == DeviceKind::kVines) return Dev::kLaw;
                                     else return ContactLaw::kKuwabara;
                                   }()),
                                   own.get());
  if (!e.ok()) return fail(tag + ": build_model: " + e.field + ": " + e.message);
  Bytes mine(img.size());
  image::write_image(*own, mine.data(), mine.size());
  // Not a check: build_model itself may round differently in another build
  // (measured: last bits of the energy ledger's input-work terms).
  std::size_t differ = 0;
  for (std::size_t i = image::kHeaderBytes; i < img.size(); ++i) differ += mine[i] != img[i];

  auto da = std::make_unique<D>(), db = std::make_unique<D>();
  init(*own, *da, static_cast<S>(rec[0]));
  init(*loaded, *db, static_cast<S>(rec[0]));
  for (std::size_t k = 1; k < rec.size(); ++k) {
    step(*own, *da, static_cast<S>(rec[k]));
    step(*loaded, *db, static_cast<S>(rec[k]));
    // The state, the particle, E_e, the top-floor peak and the counters (not
    // the ledger: see above).
    const double ea = elastic_energy(*own, *da), eb = elastic_energy(*loaded, *db);
    if (std::memcmp(da->z.data(), db->z.data(), sizeof(S) * M::kNx) != 0 || std::memcmp(&ea, &eb, sizeof ea) != 0 ||
        std::memcmp(&da->s, &db->s, sizeof(S)) != 0 || std::memcmp(&da->sd, &db->sd, sizeof(S)) != 0 ||
        std::memcmp(&da->peak_top, &db->peak_top, sizeof(S)) != 0 ||
        std::memcmp(&da->count, &db->count, sizeof da->count) != 0)
      return fail(tag + ": steps differ at step " + std::to_string(k));
  }
  std::printf("model_image_lanes1: %s: %zu bytes loaded into P = %d, written back the same; %lld contacts, "
              "same steps as this build's own model (whose image differs in %zu body bytes)\n",
              tag.c_str(), img.size(), M::kP, static_cast<long long>(da->count.contacts), differ);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: model_image_lanes1 VINES_EXE SCENES_DIR RECORD.dat WORKDIR\n");
    return 2;
  }
  const std::string exe = argv[1], scenes = argv[2], work = argv[4];
  const std::vector<double> rec = record_head(argv[3]);
  if (rec.size() != 5001) {
    std::fprintf(stderr, "model_image_lanes1: cannot read %s\n", argv[3]);
    return 1;
  }
  using Kuwabara = VinesDevice<ContactLaw::kKuwabara>;
  check<double, Kuwabara>(exe, scenes, work, "elcentro_vines", rec);
  check<float, Kuwabara>(exe, scenes, work, "elcentro_vines", rec);
  check<double, NoDevice>(exe, scenes, work, "elcentro_bare", rec);
  check<float, NoDevice>(exe, scenes, work, "elcentro_bare", rec);
  check<double, TmdDevice>(exe, scenes, work, "elcentro_tmd", rec);
  return g_failures ? 1 : 0;
}
