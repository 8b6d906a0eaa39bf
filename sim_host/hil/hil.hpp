// `vines hil`: the hardware-in-the-loop bench. It runs the firmware node
// (`vines node`, a child process) over the link protocol, streams a scene's
// record at the sensor rate in real time or lock-step with a virtual clock,
// injects link and sensor faults, and compares the telemetry with the offline
// run. Modes: replay (the scene as `vines run` runs it), twin (digital-twin
// monitor against a bench truth model, possibly damaged), hybrid (shake-table
// real-time hybrid simulation with an actuator and the VI NES on the table).
#pragma once

#include <string>
#include <vector>

#include "sim_host/hil/link/boards.hpp"
#include "sim_host/hil/link/realtime.hpp"
#include "sim_host/hil/options.hpp"
#include "sim_host/hil/report.hpp"
#include "sim_host/hil/watch.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {


// Runs the bench; returns the report (to_json in hil_report.hpp). Throws
// std::runtime_error naming the input (scene, option, node) on any error the
// user can cause. A watch (none by default) sees the run as it happens.
HilReport run_hil(const Scene& scene, const HilOptions& opt, HilWatch* watch = nullptr);

// `vines node`: the host firmware node on stdin/stdout, deadlines on the local
// clock with realtime; it gives up after idle_timeout_s without a byte. With
// listen ("tcp:[HOST:]PORT"), a node on TCP for one bench at a time, each
// connection a fresh node, until killed (throws naming the address when it
// cannot listen).
int node_main(bool realtime, double idle_timeout_s, const std::string& listen = "", const RealtimeRequest& rt = {});

}  // namespace vines::host
