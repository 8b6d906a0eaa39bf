// `vines image SCENE.toml --out FILE`: the model image a board loads.
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/cli/cli.hpp"
#include "sim_host/build_engine.hpp"
#include "sim_host/names.hpp"
#include "sim_host/scene.hpp"
#include "vines/model_image.hpp"

namespace vines::cli {
namespace {

struct ImageArgs {
  std::string scene_path, out, scalar;  // scalar "": the scene's
};

int image(const ImageArgs& a) {
  using namespace vines::host;
  const std::string& out = a.out;
  const Scene scene = load_scene(a.scene_path);
  const Scalar scalar = a.scalar.empty() ? scene.scalar : a.scalar == "float" ? Scalar::kFloat : Scalar::kDouble;
  const vines::SceneParams& p = scene.params;
  const std::vector<std::uint8_t> img = build_engine(p, scalar, scene.path)->model_image();
  vines::image::HeaderInfo h;
  if (!vines::image::read_header(img.data(), img.size(), &h)) throw std::runtime_error("no image written");
  // Checked writes: a short write or a failed close (disk full) is an error,
  // and no partial image is left behind.
  std::FILE* f = std::fopen(out.c_str(), "wb");
  if (!f) throw std::runtime_error(out + ": cannot open for writing: " + std::strerror(errno));
  const bool wrote = std::fwrite(img.data(), 1, img.size(), f) == img.size();
  const int write_errno = errno;
  const bool closed = std::fclose(f) == 0;
  if (!wrote || !closed) {
    const std::string why = std::strerror(wrote ? errno : write_errno);
    std::error_code ec;
    if (std::filesystem::is_regular_file(out, ec)) std::remove(out.c_str());
    throw std::runtime_error(out + ": cannot write: " + why);
  }
  std::string device = device_name(p.device.kind);
  if (p.device.kind == vines::DeviceKind::kVines) device += std::string(" (") + law_name(p.device.vines.law) + ")";
  std::printf("image %s: %zu bytes, version %u, %s, %u stories, %s, CRC 0x%08x; written to %s\n",
              scene.name.c_str(), img.size(), static_cast<unsigned>(h.version), h.scalar ? "float" : "double",
              static_cast<unsigned>(h.stories), device.c_str(), static_cast<unsigned>(h.crc), out.c_str());
  return kOk;
}

}  // namespace

void add_image(CLI::App& vines) {
  auto a = std::make_shared<ImageArgs>();
  CLI::App* cmd = add_command(vines, "image",
                              "Build the scene's model on this host and write its model image: what a board loads "
                              "instead of building the model itself (format: firmware/include/vines/model_image.hpp). "
                              "Prints its size, version, scalar, stories, device and CRC. The record is not read.",
                              "", [a] { return image(*a); });
  cmd->add_option("SCENE.toml", a->scene_path, "scene file (see data/scenes/README.md)")->required();
  cmd->add_option("--scalar", a->scalar, "double or float (default: the scene's scalar)")
      ->type_name("double|float")
      ->check(CLI::IsMember({"double", "float"}));
  cmd->add_option("--out", a->out, "the image file to write")
      ->type_name("FILE")
      ->required()
      ->check(CLI::Validator([](std::string& f) { return f.empty() ? "needs a file name" : ""; }, ""));
}

}  // namespace vines::cli
