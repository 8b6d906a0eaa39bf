// A bench ready to run: the options checked against the scene and their
// defaults resolved, the node chosen, the record loaded, and the node's
// configuration and model image built.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim_host/hil/link/boards.hpp"
#include "sim_host/hil/modes/twin.hpp"
#include "sim_host/hil/options.hpp"
#include "sim_host/hil/report.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"
#include "vines/link/config.hpp"

namespace vines::host {

struct Bench {
  Scene scene;                   // --duration applied; a board's scalar
  HilOptions opt;                // timeout, board image and compensation delay resolved
  const Board* board = nullptr;  // a "qemu:TARGET" node's board
  Excitation ex;
  long long samples = 0;
  double h = 0;                  // sensor period [s]
  link::NodeConfig cfg;          // what the node is configured with
  std::vector<std::uint8_t> image;  // its model image (hybrid: the hybrid frame's; twin kalman: the twin image)
  TwinBench twin;                   // twin mode: the truth, the sensors' readings, the estimator's design
};

// Throws std::runtime_error naming the input (scene, option, node).
Bench make_bench(const Scene& scene, const HilOptions& opt);

// The scene's device (report.hpp's DeviceLayout), as its model designs it.
DeviceLayout device_layout(const Scene& scene);

}  // namespace vines::host
