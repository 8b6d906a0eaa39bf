// `vines hil`'s report as text.
#pragma once

#include "sim_host/hil/report.hpp"

namespace vines::cli {

void print_hil(const host::HilReport& r);

}  // namespace vines::cli
