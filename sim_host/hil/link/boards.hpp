// The boards a "qemu:TARGET" node runs on (`vines hil --node`): the QEMU
// machine, the scalar and the preset whose build holds the board images.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim_host/hil/options.hpp"
#include "sim_host/scene/scalar.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {

struct Board {
  const char* target;
  const char* machine;
  Scalar scalar;
};

// QEMU runs the boards with -icount shift=3: one instruction per 8 ns of
// virtual time, so one tick of the MPS2's 25 MHz counter is 5 instructions,
// one of the STM32F405's 168 MHz SysTick 0.744.
inline constexpr int kIcountShift = 3;
inline double instructions_per_tick(std::uint32_t counter_hz) {
  return counter_hz ? 1e9 / counter_hz / (1 << kIcountShift) : 0.0;
}

// The nodes HilOptions::node names: "host", then "qemu:TARGET" for each board.
std::vector<std::string> node_names();
// The same as a phrase: "host, qemu:A or qemu:B".
std::string node_list();

// The board "qemu:TARGET" names, or nullptr.
const Board* board_of(const std::string& node);

// The board image for a scene's device (firmware/app: one per device; the
// twin estimator's, whatever the device): opt.image, or the preset build's. Throws naming the scene or the node.
std::string board_image(const HilOptions& opt, const Board& b, const Scene& sc);

// The QEMU command line that runs a board image.
std::vector<std::string> qemu_argv(const Board& b, const std::string& image);

}  // namespace vines::host
