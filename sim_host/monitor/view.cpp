#include "sim_host/monitor/view.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "sim_host/monitor/decimator.hpp"
#include "sim_host/monitor/rows.hpp"
#include "sim_host/monitor/watch.hpp"

namespace vines::host::monitor {
namespace {

namespace fs = std::filesystem;

// The CSV a path names: itself, or a folder's only .csv.
std::string find_csv(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return path;
  if (!fs::is_directory(path, ec)) throw std::runtime_error(path + ": no such file or folder");
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(path, ec))
    if (e.path().extension() == ".csv") found.push_back(e.path().string());
  if (found.size() != 1)
    throw std::runtime_error(path + ": a folder with " + std::to_string(found.size()) +
                             " .csv files (give the run's --csv file itself)");
  return found[0];
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
  return cells;
}

}  // namespace

void load_run(const std::string& path, Hub* hub) {
  const std::string file = find_csv(path);
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) throw std::runtime_error(file + ": cannot be read, or empty");
  const std::vector<std::string> header = split(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t j = 0; j < header.size(); ++j) col[header[j]] = j;
  for (const char* need : {"k", "t_s", "received", "ag_sent_mps2", "x_top_m"})
    if (!col.count(need)) throw std::runtime_error(file + ": not a `vines hil --csv` file (no column " + need + ")");
  // The rows as numbers.
  std::vector<std::vector<double>> rows;
  for (long long r = 2; std::getline(in, line); ++r) {
    if (line.empty()) continue;
    std::vector<std::string> cells = split(line);
    if (cells.size() != header.size())
      throw std::runtime_error(file + ": row " + std::to_string(r) + " has " + std::to_string(cells.size()) +
                               " cells for " + std::to_string(header.size()) + " columns");
    std::vector<double> v(cells.size());
    for (std::size_t j = 0; j < cells.size(); ++j) {
      char* end = nullptr;
      v[j] = std::strtod(cells[j].c_str(), &end);
      if (cells[j].empty() || *end != '\0')
        throw std::runtime_error(file + ": row " + std::to_string(r) + ", column " + header[j] + ": '" + cells[j] +
                                 "' is not a number");
    }
    rows.push_back(std::move(v));
  }
  if (rows.size() < 2) throw std::runtime_error(file + ": fewer than two samples");
  const auto at = [&](std::size_t row, const char* name) { return rows[row][col.at(name)]; };
  // The mode and the device from the columns there are.
  const bool twin = col.count("x_top_truth_m") > 0, hybrid = col.count("table_x_m") > 0;
  DeviceKind device = DeviceKind::kNone;
  if (col.count("eta_tmd")) device = DeviceKind::kTmd;
  else if (col.count("eta_device_floor_mass")) device = DeviceKind::kVines;
  else if (col.count("contact_force_n") && col.count("particle_x_m"))
    for (std::size_t r = 0; r < rows.size() && device != DeviceKind::kVines; ++r) {
      if (at(r, "contact_force_n") != 0) device = DeviceKind::kVines;
      else if (at(r, "particle_x_m") != 0) device = DeviceKind::kTmd;
    }
  PageMeta m;
  m.source = file;
  m.mode = twin ? "twin" : hybrid ? "hybrid" : "replay";
  m.live = false;
  m.rate_hz = 1 / (at(1, "t_s") - at(0, "t_s"));
  m.every = page_every(m.rate_hz);
  // The series in the order the live page has them (rows.cpp).
  const DeviceSeries ds = device_series(m.mode, device, col.count("alarm_story") > 0);
  std::vector<std::string> factors, floors;
  for (const std::string& h : header) {
    if (twin && h.rfind("eta_", 0) == 0 && h.rfind("eta_sd_", 0) != 0) factors.push_back(h);
    // The floors chosen (--floors): describe() knows them as floors.
    if (describe(h, m.mode, device).panel == "floors" && h.rfind("x_", 0) == 0 && h != "x_top_m" &&
        h != "x_top_offline_m" && h != "x_top_truth_m")
      floors.push_back(h);
  }
  std::vector<std::string> names = series_names(m.mode, ds, factors, floors);
  // The decision's (a CSV of an earlier version has no statistics: the page
  // says so; the twin's --csv has no sizes or onset).
  if (col.count("alarm_story"))
    for (const std::string& n : decision_names(factors)) names.push_back(n);
  // Those the file has (the tracking RMS: from the table and the top floor).
  names.erase(std::remove_if(names.begin(), names.end(),
                             [&](const std::string& n) { return n != "tracking_rms_pct" && !col.count(n); }),
              names.end());
  for (const std::string& n : names) m.series.push_back(describe(n, m.mode, device));
  // The stories: the twin estimator's story factors (eta_1 ...), else not in the CSV.
  m.stories = static_cast<int>(std::count_if(factors.begin(), factors.end(), [](const std::string& f) {
    return f.find_first_not_of("0123456789", 4) == std::string::npos;
  }));
  // The device's panel: the CSV names neither the device's floor nor its
  // box, so the page draws it relative to the top floor (labelled so) and
  // without the walls.
  if (device != DeviceKind::kNone) {
    m.device = device == DeviceKind::kTmd ? "tmd" : "vines";
    m.device_floor_series = "x_top_m";
  }
  hub->set_header(sse_event("meta", to_json(m).dump()));
  // The frames: the samples received, kept as the live run keeps them.
  Decimator dec(m.every, kFrameSamples, names.size());
  const int contact = event_series(names, ds);
  RunningTracking tracking;
  std::vector<double> v;
  std::string event;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (at(r, "received") == 0) continue;
    const auto k = static_cast<long long>(at(r, "k"));
    if (hybrid) tracking.add(at(r, "x_top_m"), at(r, "table_x_m"));
    v.clear();
    for (const std::string& n : names) v.push_back(n == "tracking_rms_pct" ? tracking.pct() : rows[r][col.at(n)]);
    if (!dec.keeps(k, contact >= 0 && v[static_cast<std::size_t>(contact)] != 0)) continue;
    if (dec.add(k, v, &event)) hub->publish(std::move(event));
  }
  if (dec.flush(&event)) hub->publish(std::move(event));
  hub->publish(sse_event("end", "{}"));
  hub->close();
}

}  // namespace vines::host::monitor
