// `vines image SCENE.toml --out FILE`: the model image a board loads.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/io/output.hpp"
#include "sim_host/scene/names.hpp"
#include "sim_host/scene/scene.hpp"
#include "vines/bytes/crc32.hpp"
#include "vines/fixed/image.hpp"
#include "vines/image/model_image.hpp"

namespace vines::cli {
namespace {

struct ImageArgs {
  std::string scene_path, out, scalar;  // scalar "": the scene's
};

int image(const ImageArgs& a) {
  using namespace vines::host;
  const std::string& out = a.out;
  const Scene scene = load_scene(a.scene_path);
  const Scalar scalar = a.scalar.empty() ? scene.scalar
                        : a.scalar == "float"   ? Scalar::kFloat
                        : a.scalar == "fixed"   ? Scalar::kFixed
                                                : Scalar::kDouble;
  const vines::SceneParams& p = scene.params;
  const std::vector<std::uint8_t> img = build_engine(p, scalar, scene.path)->model_image();
  std::string device = device_name(p.device.kind);
  if (p.device.kind == vines::DeviceKind::kVines) device += std::string(" (") + law_name(p.device.vines.law) + ")";
  std::string what;
  if (scalar == Scalar::kFixed) {
    if (!vines::fixed::is_fixed_image(img.data(), img.size())) throw std::runtime_error("no image written");
    const std::uint32_t crc = vines::link::crc32(img.data() + vines::fixed::kImageHeaderBytes,
                                                 img.size() - vines::fixed::kImageHeaderBytes);
    char line[200];
    std::snprintf(line, sizeof line, "%zu bytes, fixed-point (Q3.28) version %u, %d stories, %s, CRC 0x%08x",
                  img.size(), static_cast<unsigned>(vines::fixed::kImageVersion), p.frame.stories, device.c_str(),
                  static_cast<unsigned>(crc));
    what = line;
  } else {
    vines::image::HeaderInfo h;
    if (!vines::image::read_header(img.data(), img.size(), &h)) throw std::runtime_error("no image written");
    char line[200];
    std::snprintf(line, sizeof line, "%zu bytes, version %u, %s, %u stories, %s, CRC 0x%08x", img.size(),
                  static_cast<unsigned>(h.version), h.scalar ? "float" : "double", static_cast<unsigned>(h.stories),
                  device.c_str(), static_cast<unsigned>(h.crc));
    what = line;
  }
  // Checked and atomic: a failed write (disk full) leaves no partial image.
  AtomicFile f(out);
  f.write(reinterpret_cast<const char*>(img.data()), img.size());
  f.commit();
  std::printf("image %s: %s; written to %s\n", scene.name.c_str(), what.c_str(), out.c_str());
  return kOk;
}

}  // namespace

void add_image(CLI::App& vines) {
  auto a = std::make_shared<ImageArgs>();
  CLI::App* cmd = add_command(vines, "image",
                              "Build the scene's model on this host and write its model image: what a board loads "
                              "instead of building the model itself (format: firmware/include/vines/image/model_image.hpp; "
                              "in fixed point firmware/include/vines/fixed/image.hpp). "
                              "Prints its size, version, scalar, stories, device and CRC. The record is not read.",
                              "", [a] { return image(*a); });
  cmd->add_option("SCENE.toml", a->scene_path, "scene file (see data/scenes/README.md)")->required();
  cmd->add_option("--scalar", a->scalar, "double, float or fixed (default: the scene's scalar)")
      ->type_name("double|float|fixed")
      ->check(CLI::IsMember({"double", "float", "fixed"}));
  cmd->add_option("--out", a->out, "the image file to write")
      ->type_name("FILE")
      ->required()
      ->check(non_empty_path());
}

}  // namespace vines::cli
