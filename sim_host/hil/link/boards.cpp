#include "sim_host/hil/link/boards.hpp"

#include <fstream>
#include <stdexcept>

#include "sim_host/hil/options.hpp"

namespace vines::host {
namespace {

constexpr Board kBoards[] = {
#include "boards_table.inc"
};

}  // namespace

std::vector<std::string> node_names() {
  std::vector<std::string> names = {"host"};
  for (const Board& b : kBoards) names.push_back(std::string("qemu:") + b.target);
  return names;
}

std::string node_list() {
  const std::vector<std::string> names = node_names();
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}

const Board* board_of(const std::string& node) {
  for (const Board& b : kBoards)
    if (node == std::string("qemu:") + b.target) return &b;
  return nullptr;
}

std::string board_image(const HilOptions& opt, const Board& b, const Scene& sc) {
  std::string dev;
  const DeviceParams& d = sc.params.device;
  if (opt.mode == HilMode::kTwin && opt.estimator == HilEstimator::kKalman) dev = "twin";
  else if (d.kind == DeviceKind::kNone) dev = "none";
  else if (d.kind == DeviceKind::kTmd) dev = "tmd";
  else dev = law_name(d.vines.law);  // vines_node_LAW.elf, one per law built (VINES_NODE_LAWS)
  if (dev == "twin" && sc.params.frame.stories > 10)
    throw std::runtime_error(sc.path + ": --node " + opt.node + ": the twin image holds up to 10 stories");
  if (dev != "twin" && sc.params.frame.stories != 10)
    throw std::runtime_error(sc.path + ": --node " + opt.node + ": the board images are built for 10 stories");
  const std::string path = !opt.image.empty() ? opt.image
                                              : std::string(VINES_SOURCE_DIR) + "/build/" + b.target +
                                                    "/firmware/app/vines_node_" + dev + ".elf";
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    const bool law = d.kind == DeviceKind::kVines && dev != "twin";
    throw std::runtime_error("--node " + opt.node + ": no board image " + path + " (build it: cmake --preset " +
                             b.target + (law ? " -DVINES_NODE_LAWS=" + dev : "") + " && cmake --build --preset " +
                             b.target + ")");
  }
  // A 32-bit little-endian ARM ELF executable (e_machine 40), or QEMU would
  // fail on it with a register dump that names nothing.
  unsigned char h[20] = {};
  f.read(reinterpret_cast<char*>(h), sizeof h);
  const bool elf = f.gcount() == sizeof h && h[0] == 0x7f && h[1] == 'E' && h[2] == 'L' && h[3] == 'F';
  if (!elf || h[4] != 1 || h[5] != 1 || h[16] != 2 || h[18] != 40)
    throw std::runtime_error("--image " + path + ": not a board image (a 32-bit ARM ELF executable, as " +
                             b.target + "'s build makes)");
  return path;
}

std::vector<std::string> qemu_argv(const Board& b, const std::string& image) {
  return {"qemu-system-arm", "-M", b.machine, "-display", "none", "-monitor", "none",
          "-semihosting-config", "enable=on,target=native", "-serial", "stdio",
          "-icount", "shift=" + std::to_string(kIcountShift) + ",align=off,sleep=off", "-kernel", image};
}

}  // namespace vines::host
