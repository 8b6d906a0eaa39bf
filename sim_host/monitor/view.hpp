// `vines view`: a finished run's --csv (`vines hil ... --csv FILE`) read back
// into the page's events, as the live run sent them: the same series (those
// of its columns the page shows, and the hybrid tracking RMS computed as the
// bench does), the same kept samples, the same frames; then `end`.
#pragma once

#include <string>

#include "sim_host/monitor/hub.hpp"

namespace vines::host::monitor {

// PATH: the CSV, or a folder holding exactly one .csv. Throws
// std::runtime_error naming the path (missing, not a `vines hil` CSV, a cell
// that is not a number: its row and column).
void load_run(const std::string& path, Hub* hub);

}  // namespace vines::host::monitor
