#include "sim_host/hil/modes/twin_baseline.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include "sim_host/io/output.hpp"
#include "sim_host/scene/names.hpp"

namespace vines::host {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "vines twin baseline";
constexpr int kVersion = 1;

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw std::runtime_error("twin baseline " + path + ": " + why);
}

std::vector<double> numbers(const json& j, const char* key, std::size_t n, const std::string& path) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != n)
    fail(path, std::string("a run's ") + key + ": not a list of " + std::to_string(n) + " numbers");
  std::vector<double> v;
  for (const json& x : j[key]) {
    if (!x.is_number() || !std::isfinite(x.get<double>())) fail(path, std::string("a run's ") + key + ": a value not finite");
    v.push_back(x.get<double>());
  }
  return v;
}

// The file's JSON, checked against the building; a missing file with
// may_be_missing: a new baseline.
json read(const std::string& path, const TwinBuilding& b, bool may_be_missing) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (!may_be_missing) fail(path, "no such file");
    return json{{"format", kFormat}, {"version", kVersion}, {"stories", b.stories}, {"device", b.device},
                {"sensors", b.sensors}, {"sensor_rate_hz", b.sensor_rate_hz}, {"runs", json::array()}};
  }
  if (!S_ISREG(st.st_mode)) fail(path, "not a regular file");
  if (st.st_size > (16 << 20)) fail(path, "larger than 16 MiB: not a baseline");
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  json j = json::parse(ss.str(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("format", "") != kFormat)
    fail(path, "not a twin baseline (vines hil --mode twin --commission writes one)");
  if (j.value("version", 0) != kVersion)
    fail(path, "baseline version " + j.value("version", json(0)).dump() + ", this program reads version " +
                   std::to_string(kVersion));
  auto same = [&](const char* key, const json& want) {
    if (!j.contains(key) || j[key] != want)
      fail(path, std::string("a baseline of another building: its ") + key + " is " +
                     (j.contains(key) ? j[key].dump() : "missing") + ", this twin's " + want.dump());
  };
  same("stories", b.stories);
  same("device", b.device);
  same("sensors", b.sensors);
  same("sensor_rate_hz", b.sensor_rate_hz);
  if (!j.contains("runs") || !j["runs"].is_array()) fail(path, "no runs list");
  for (const json& r : j["runs"]) {
    if (!r.is_object()) fail(path, "a run is not an object");
    numbers(r, "loss", static_cast<std::size_t>(b.stories), path);
    numbers(r, "loss_sd", static_cast<std::size_t>(b.stories), path);
  }
  return j;
}

}  // namespace

TwinBuilding twin_building(const Scene& node, const HilOptions& o) {
  TwinBuilding b;
  b.stories = node.params.frame.stories;
  b.device = device_name(node.params.device.kind);
  b.sensors = o.sensors.empty() ? std::vector<int>{b.stories} : o.sensors;
  b.sensor_rate_hz = node.params.loop.sensor_rate_hz;
  return b;
}

TwinBaselineStats load_twin_baseline(const std::string& path, const TwinBuilding& b, const TwinTuning& t) {
  const json j = read(path, b, false);
  const auto n = static_cast<std::size_t>(b.stories);
  const std::size_t runs = j["runs"].size();
  if (runs == 0) fail(path, "no run: commission it on at least one healthy record first");
  std::vector<std::vector<double>> loss, sd;
  for (const json& r : j["runs"]) loss.push_back(numbers(r, "loss", n, path)), sd.push_back(numbers(r, "loss_sd", n, path));
  TwinBaselineStats s;
  s.loss.assign(n, 0.0);
  s.cov.assign(n, std::vector<double>(n, 0.0));
  for (const auto& l : loss)
    for (std::size_t a = 0; a < n; ++a) s.loss[a] += l[a] / static_cast<double>(runs);
  if (runs > 1) {
    const double scale = (1.0 + 1.0 / static_cast<double>(runs)) / static_cast<double>(runs - 1);
    for (const auto& l : loss)
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t c = 0; c < n; ++c) s.cov[a][c] += scale * (l[a] - s.loss[a]) * (l[c] - s.loss[c]);
  }
  s.runs = static_cast<int>(runs);
  for (std::size_t a = 0; a < n; ++a) {
    double v = 0;
    for (const auto& e : sd) v += e[a] * e[a] / static_cast<double>(runs);
    s.cov[a][a] += t.inflation * v;
  }
  return s;
}

void check_commission_file(const std::string& path, const TwinBuilding& b) { read(path, b, true); }

void commission_twin(const std::string& path, const TwinBuilding& b, const HilTwinReport& run,
                     const std::string& record) {
  json j = read(path, b, true);
  // A run the twin's model does not explain is no picture of the healthy
  // building: its estimates would widen (or shift) the baseline.
  if (!run.caveat.empty()) fail(path, "this run is not added to it: " + run.caveat);
  json r = {{"truth", run.truth}, {"record", record}, {"loss", json::array()}, {"loss_sd", run.eta_k_sd}};
  for (double e : run.eta_k) r["loss"].push_back(1.0 - e);
  j["runs"].push_back(r);
  write_file_atomic(path, j.dump(1) + "\n");
}

}  // namespace vines::host
