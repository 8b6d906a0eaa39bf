// The page's files, compiled into the program (sim_host/CMakeLists.txt
// generates page_assets.cpp from sim_host/monitor/page/ and the vendored
// uPlot in third_party/uplot/): nothing to find at run time, no CDN.
#pragma once

#include <string_view>
#include <vector>

namespace vines::host::monitor {

struct PageFile {
  std::string_view path;  // as requested: "/", "/app.js", ...
  std::string_view type;  // its media type (text/html, ...), UTF-8
  std::string_view body;
};

const std::vector<PageFile>& page_files();

}  // namespace vines::host::monitor
