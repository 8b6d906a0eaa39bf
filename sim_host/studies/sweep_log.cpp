// DIR/runs.jsonl: the finished runs of a sweep, appended as they finish
// (format in sweep_log.hpp).
#include "sim_host/studies/sweep_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/io/digest.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/scene/table.hpp"

namespace vines::host {
namespace {

using nlohmann::json;

constexpr int kLogVersion = 2;

#ifndef VINES_VERSION
#error "VINES_VERSION: the program's version (sim_host/CMakeLists.txt)"
#endif

// A run's line: the JSON object {"run": I, "result": {...}} with, last, the
// digest of its text before that member: {"run":I,"result":{...},"check":"HEX"}.
constexpr const char* kCheck = ",\"check\":\"";

// The line's JSON text without its check, or why it does not hold.
std::string unchecked(const std::string& line) {
  const std::size_t at = line.rfind(kCheck);
  const std::size_t hex = at + std::strlen(kCheck);
  if (at == std::string::npos || line.size() != hex + 16 + 2 || line.compare(hex + 16, 2, "\"}") != 0)
    throw std::runtime_error("no check at its end");
  const std::string body = line.substr(0, at) + "}";
  Digest d;
  d.add(body);
  if (line.compare(hex, 16, d.hex()) != 0) throw std::runtime_error("its check does not match its text (damaged)");
  return body;
}

// JSON has no NaN or infinity: a result's non-finite numbers go as text and
// come back as numbers (only the members that are numbers in a RunResult).
const char* nonfinite_text(double x) { return std::isnan(x) ? "nan" : x > 0 ? "inf" : "-inf"; }

json result_json(const RunResult& r) {
  json j = r;
  for (auto& item : j.items())
    if (item.value().is_number_float() && !std::isfinite(item.value().get<double>()))
      item.value() = nonfinite_text(item.value().get<double>());
  return j;
}

// A logged result, every member present with its type (a float member may
// be "nan", "inf" or "-inf"), no other member, finished.
RunResult result_from(json j) {
  static const json kDefault = RunResult{};
  if (!j.is_object()) throw std::runtime_error("its result is not an object");
  for (const auto& item : j.items())
    if (!kDefault.contains(item.key())) throw std::runtime_error("its result has an unknown member \"" + item.key() + "\"");
  for (const auto& want : kDefault.items()) {
    if (!j.contains(want.key())) throw std::runtime_error("its result lacks \"" + want.key() + "\"");
    json& v = j[want.key()];
    const std::string& key = want.key();
    if (want.value().is_number_float()) {
      if (v.is_string()) {
        const std::string t = v.get<std::string>();
        const double inf = std::numeric_limits<double>::infinity();
        if (t != "nan" && t != "inf" && t != "-inf") throw std::runtime_error("\"" + key + "\" is not a number");
        v = t == "inf" ? inf : t == "-inf" ? -inf : std::numeric_limits<double>::quiet_NaN();
      } else if (!v.is_number()) {
        throw std::runtime_error("\"" + key + "\" is not a number");
      }
    } else if (want.value().is_number_integer()) {
      if (!v.is_number_integer() || v.get<long long>() < 0) throw std::runtime_error("\"" + key + "\" is not a count");
    } else if (want.value().type() != v.type()) {
      throw std::runtime_error("\"" + key + "\" is not a " + want.value().type_name());
    }
  }
  RunResult r = j.get<RunResult>();
  if (!r.done) throw std::runtime_error("its result is not finished (\"done\": false)");
  return r;
}

}  // namespace

std::string checked_log_line(const std::string& body) {
  Digest d;
  d.add(body);
  return body.substr(0, body.size() - 1) + kCheck + d.hex() + "\"}\n";
}

std::string plan_fingerprint(const SweepSpec& spec, const std::vector<RunPlan>& plan) {
  Digest d;
  d.add("vines sweep plan " + std::to_string(kLogVersion) + " vines " VINES_VERSION);
  // Each study's settings, its scene file (wherever the sweep is started from) and the
  // scene as parsed (toml++ prints it in a fixed order).
  for (const StudySpec& st : spec.studies) {
    const toml::table table = read_scene_table(st.scene_path);
    std::ostringstream scene;
    scene << table;
    const std::string where = std::filesystem::weakly_canonical(st.scene_path).string();
    for (const std::string& s : {st.name, where, st.group_by, st.optimize, scene.str()}) d.add(s);
    for (const KeyValue& v : st.set) d.add(v.key + "=" + v.label());
    // Every record file the study reads, by its bytes: a record changed
    // between a sweep and its resume would mix old and new runs.
    std::vector<std::string> records;
    const toml::table own = st.scene_toml.empty() ? toml::table{} : parse_scene_table(st.scene_toml, st.scene_path);
    if (const auto* path = (st.scene_toml.empty() ? table : own)["record"]["path"].as_string())
      records.push_back(path->get());
    auto files = [&](const std::vector<KeyValue>& vs) {
      for (const KeyValue& v : vs)
        if (v.record_file) records.push_back(v.text);
    };
    files(st.set);
    for (const auto& c : st.cases) files(c);
    for (const auto& axis : st.grid_axes) files(axis);
    std::sort(records.begin(), records.end());
    records.erase(std::unique(records.begin(), records.end()), records.end());
    for (const std::string& rec : records) {
      d.add(rec);
      try {
        if (!d.add_file(resolve_record_path(rec, st.scene_path))) d.add("unreadable");
      } catch (const std::exception&) {
        d.add("not found");  // the runs say so
      }
    }
  }
  // Every run: its study and keys, in plan order.
  for (const RunPlan& r : plan) {
    d.add(std::to_string(r.study));
    for (const KeyValue& v : r.values) d.add(v.column() + "=" + v.label());
  }
  return d.hex();
}

SweepLogContents read_sweep_log(const std::string& file, const std::string& fingerprint, std::size_t runs) {
  // A regular file, read whole (no size bound: a --large plan's log may be big).
  const std::string text = hal::read_input_file(file, std::numeric_limits<std::uintmax_t>::max());
  SweepLogContents out;
  out.results.resize(runs);
  std::vector<std::size_t> seen(runs, 0);  // the line of each run read
  std::size_t line_no = 0;
  for (std::size_t start = 0; start < text.size(); ++line_no) {
    const std::size_t nl = text.find('\n', start);
    const std::string line = text.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
    const std::string where = file + ":" + std::to_string(line_no + 1);
    // The header: this spec and plan, or a refusal.
    if (line_no == 0) {
      const json h = json::parse(line, nullptr, false);
      if (nl == std::string::npos || !h.is_object() || h.value("vines_sweep_log", 0) != kLogVersion)
        throw std::runtime_error(where + ": not a vines sweep log (no header line)");
      if (h.value("fingerprint", "") != fingerprint || h.value("runs", std::size_t{0}) != runs)
        throw std::runtime_error(file + ": the log is of another spec or plan (" + h.value("spec", "?") + ", " +
                                 std::to_string(h.value("runs", 0)) + " runs): refusing to resume from it");
      start = nl + 1;
      out.good_bytes = start;
      continue;
    }
    // A run: checked, its index in the plan and not seen before, its result
    // whole and finished. Only a last line without its end (a write torn by
    // a power cut) is left out; any other bad line stops the resume.
    try {
      if (nl == std::string::npos) throw std::runtime_error("no end of line");
      const json j = json::parse(unchecked(line));
      if (!j.is_object() || j.size() != 2 || !j.contains("run") || !j.contains("result"))
        throw std::runtime_error("not a run's line");
      if (!j["run"].is_number_unsigned()) throw std::runtime_error("its run is not an index");
      const std::size_t i = j["run"].get<std::size_t>();
      if (i >= runs) throw std::runtime_error("run " + std::to_string(i) + " is not in the plan");
      if (seen[i] != 0)
        throw std::runtime_error("run " + std::to_string(i) + " is also on line " + std::to_string(seen[i]));
      out.results[i] = result_from(j["result"]);
      seen[i] = line_no + 1;
      ++out.finished;
    } catch (const std::exception& e) {
      if (nl != std::string::npos) throw std::runtime_error(where + ": bad line in the log: " + e.what());
      out.warning = where + ": torn last line left out (" + e.what() + "); that run runs again";
      break;
    }
    start = nl + 1;
    out.good_bytes = start;
  }
  if (line_no == 0) throw std::runtime_error(file + ": empty: not a vines sweep log");
  return out;
}

SweepLog::SweepLog(const std::string& file, const std::string& spec, const std::string& fingerprint,
                   std::size_t runs, std::size_t keep_bytes)
    : file_(file) {
  // A new log starts with its header; a resumed one drops its torn tail.
  // Never through a link (O_NOFOLLOW; the folder's claim refused links and
  // hard links already, output.hpp).
  const int flags = O_WRONLY | O_APPEND | O_CLOEXEC | O_NOFOLLOW | (keep_bytes == 0 ? O_CREAT | O_TRUNC : 0);
  fd_ = ::open(file.c_str(), flags, 0644);
  if (fd_ < 0 && errno == ELOOP) throw std::runtime_error(file_ + ": cannot open: a symbolic link");
  if (fd_ < 0) fail("cannot open", errno);
  if (keep_bytes > 0 && ::ftruncate(fd_, static_cast<off_t>(keep_bytes)) != 0) fail("cannot cut the torn line", errno);
  if (keep_bytes == 0) {
    const json h = {{"vines_sweep_log", kLogVersion}, {"spec", spec}, {"fingerprint", fingerprint}, {"runs", runs}};
    write_line(h.dump() + '\n');
  }
  syncer_ = std::thread([this] { sync_loop(); });
}

SweepLog::~SweepLog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  wake_.notify_all();
  if (syncer_.joinable()) syncer_.join();
  if (fd_ >= 0) ::close(fd_);
}

void SweepLog::append(std::size_t run, const RunResult& result) {
  const std::string line = checked_log_line(json{{"run", run}, {"result", result_json(result)}}.dump());
  std::lock_guard<std::mutex> lock(mutex_);
  if (sync_error_ != 0) fail("cannot sync to disk", sync_error_);
  write_line(line);
  dirty_ = true;
}

void SweepLog::close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  wake_.notify_all();
  if (syncer_.joinable()) syncer_.join();
  if (sync_error_ != 0) fail("cannot sync to disk", sync_error_);
  if (::fdatasync(fd_) != 0) fail("cannot sync to disk", errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail("cannot close", errno);
}

// One write(2) per line (retried on a short write): a kill leaves whole
// lines and at most one torn last line.
void SweepLog::write_line(const std::string& line) {
  for (std::size_t done = 0; done < line.size();) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail("cannot write", errno);
    done += static_cast<std::size_t>(n);
  }
}

// Every 0.2 s, the rows written since the last sync go to disk.
void SweepLog::sync_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!closing_) {
    wake_.wait_for(lock, std::chrono::milliseconds(200), [this] { return closing_; });
    if (!dirty_ || sync_error_ != 0) continue;
    dirty_ = false;
    lock.unlock();
    const int rc = ::fdatasync(fd_), err = errno;
    lock.lock();
    if (rc != 0) sync_error_ = err;
  }
}

void SweepLog::fail(const std::string& what, int err) const {
  throw std::runtime_error(file_ + ": " + what + ": " + std::strerror(err));
}

}  // namespace vines::host
