#include "sim_host/monitor/view.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
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
  const fs::file_status st = fs::status(path, ec);
  if (fs::is_regular_file(st)) return path;
  if (!fs::exists(st)) throw std::runtime_error(path + ": no such file or folder");
  if (!fs::is_directory(st))
    throw std::runtime_error(path + ": not a regular file (a FIFO, a device or a socket): give a run's --csv file");
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
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

// A line without its end (LF or CRLF); false at the end of the file.
bool next_line(std::istream& in, std::string* line) {
  if (!std::getline(in, *line)) return false;
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return true;
}

constexpr std::size_t kMaxColumns = 4096;

// The run's own description beside its CSV (FILE.json, written by `vines
// hil --csv`), if there; refused if it is not one or describes another file.
std::optional<nlohmann::json> read_meta(const std::string& file, std::size_t columns) {
  const std::string path = file + ".json";
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  std::ifstream in(path);
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("format", "") != "vines hil --csv")
    throw std::runtime_error(path + ": not the description `vines hil --csv` writes beside its CSV");
  try {
    if (j.at("columns").get<std::size_t>() != columns)
      throw std::runtime_error(path + ": describes a CSV of " + j.at("columns").dump() + " columns; " + file +
                               " has " + std::to_string(columns) + " (not the file it was written with)");
    const double rate = j.at("sensor_rate_hz").get<double>();
    if (!(rate > 0 && rate <= 1e6)) throw std::runtime_error(path + ": sensor_rate_hz " + j.at("sensor_rate_hz").dump());
    const std::string mode = j.at("mode").get<std::string>(), kind = j.at("device").at("kind").get<std::string>();
    if (mode != "replay" && mode != "twin" && mode != "hybrid") throw std::runtime_error(path + ": mode '" + mode + "'");
    if (kind != "none" && kind != "tmd" && kind != "vines") throw std::runtime_error(path + ": device kind '" + kind + "'");
    const int stories = j.at("stories").get<int>(), floor = j.at("device").at("floor").get<int>();
    if (stories < 1 || stories > 64 || floor < 0 || floor > stories)
      throw std::runtime_error(path + ": stories " + std::to_string(stories) + ", device floor " + std::to_string(floor));
    j.at("device").at("gap_m").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return j;
}

}  // namespace

void load_run(const std::string& path, Hub* hub) {
  const std::string file = find_csv(path);
  std::ifstream in(file);
  std::string line;
  if (!in || !next_line(in, &line)) throw std::runtime_error(file + ": cannot be read, or empty");
  const std::vector<std::string> header = split(line);
  if (header.size() > kMaxColumns)
    throw std::runtime_error(file + ": line 1 has " + std::to_string(header.size()) + " columns (at most " +
                             std::to_string(kMaxColumns) + ")");
  std::map<std::string, std::size_t> col;
  for (std::size_t j = 0; j < header.size(); ++j)
    if (!col.emplace(header[j], j).second)
      throw std::runtime_error(file + ": line 1: column " + std::to_string(j + 1) + " is '" + header[j] +
                               "' again (column " + std::to_string(col[header[j]] + 1) + ")");
  for (const char* need : {"k", "t_s", "received", "ag_sent_mps2", "x_top_m"})
    if (!col.count(need)) throw std::runtime_error(file + ": not a `vines hil --csv` file (no column " + need + ")");
  const std::optional<nlohmann::json> meta = read_meta(file, header.size());
  // The rows as numbers; the sample index, its time and whether it came
  // checked (each a line and a column named).
  const std::size_t ck = col["k"], ct = col["t_s"], cr = col["received"];
  std::vector<std::vector<double>> rows;
  for (long long r = 2; next_line(in, &line); ++r) {
    if (line.empty()) continue;
    std::vector<std::string> cells = split(line);
    const std::string where = file + ": line " + std::to_string(r) + ", column ";
    if (cells.size() != header.size())
      throw std::runtime_error(file + ": line " + std::to_string(r) + " has " + std::to_string(cells.size()) +
                               " cells for " + std::to_string(header.size()) + " columns");
    std::vector<double> v(cells.size());
    for (std::size_t j = 0; j < cells.size(); ++j) {
      char* end = nullptr;
      v[j] = std::strtod(cells[j].c_str(), &end);
      if (cells[j].empty() || *end != '\0')
        throw std::runtime_error(where + header[j] + ": '" + cells[j] + "' is not a number");
    }
    const double k = v[ck], t = v[ct];
    if (!(k >= 0 && k < 1e15 && k == std::floor(k)) || (!rows.empty() && !(k > rows.back()[ck])))
      throw std::runtime_error(where + "k: '" + cells[ck] + "' is not the next sample's index (an integer from 0, rising)");
    if (!std::isfinite(t) || (!rows.empty() && !(t > rows.back()[ct])))
      throw std::runtime_error(where + "t_s: '" + cells[ct] + "' is not a time after the line before's");
    if (v[cr] != 0 && v[cr] != 1) throw std::runtime_error(where + "received: '" + cells[cr] + "' is neither 0 nor 1");
    rows.push_back(std::move(v));
  }
  if (rows.size() < 2) throw std::runtime_error(file + ": fewer than two samples");
  const auto at = [&](std::size_t row, const char* name) { return rows[row][col.at(name)]; };
  // The mode, the rate and the device: as the run wrote them beside its CSV,
  // else from the columns there are (the rate from the times' whole span:
  // they are written to the microsecond).
  const bool twin = col.count("x_top_truth_m") > 0, hybrid = col.count("table_x_m") > 0;
  DeviceKind device = DeviceKind::kNone;
  if (meta) {
    const std::string kind = (*meta)["device"]["kind"];
    device = kind == "tmd" ? DeviceKind::kTmd : kind == "vines" ? DeviceKind::kVines : DeviceKind::kNone;
  } else if (col.count("eta_tmd")) {
    device = DeviceKind::kTmd;
  } else if (col.count("eta_device_floor_mass")) {
    device = DeviceKind::kVines;
  } else if (col.count("contact_force_n") && col.count("particle_x_m")) {
    for (std::size_t r = 0; r < rows.size() && device != DeviceKind::kVines; ++r) {
      if (at(r, "contact_force_n") != 0) device = DeviceKind::kVines;
      else if (at(r, "particle_x_m") != 0) device = DeviceKind::kTmd;
    }
  }
  PageMeta m;
  m.source = file;
  m.mode = meta ? (*meta)["mode"].get<std::string>() : twin ? "twin" : hybrid ? "hybrid" : "replay";
  m.live = false;
  m.rate_hz = meta ? (*meta)["sensor_rate_hz"].get<double>()
                   : (at(rows.size() - 1, "k") - at(0, "k")) / (at(rows.size() - 1, "t_s") - at(0, "t_s"));
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
  // The stories: the run's, else the twin estimator's story factors (eta_1
  // ...), else not in the CSV.
  m.stories = meta ? (*meta)["stories"].get<int>()
                   : static_cast<int>(std::count_if(factors.begin(), factors.end(), [](const std::string& f) {
                       return f.find_first_not_of("0123456789", 4) == std::string::npos;
                     }));
  // The device's panel: the floor it sits on and the VI NES box's walls as
  // the run wrote them; without them the page draws it relative to the top
  // floor (labelled so) and without the walls.
  if (device != DeviceKind::kNone) {
    m.device = device == DeviceKind::kTmd ? "tmd" : "vines";
    m.device_floor_series = "x_top_m";
    if (meta) {
      m.device_floor_series = device_floor_series((*meta)["device"]["floor"], m.stories, header);
      m.gap_m = (*meta)["device"]["gap_m"];
    }
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
