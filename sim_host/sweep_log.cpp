// DIR/runs.jsonl: the finished runs of a sweep, appended as they finish
// (format in sweep_log.hpp).
#include "sim_host/sweep_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <toml++/toml.h>

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
#include "sim_host/scene_toml.hpp"

namespace vines::host {
namespace {

using nlohmann::json;

constexpr int kLogVersion = 1;

// FNV-1a, 64 bits: a digest of text, the same on every build.
class Digest {
 public:
  void add(const std::string& text) {
    for (unsigned char c : text) h_ = (h_ ^ c) * 0x100000001b3ULL;
    h_ = (h_ ^ 0xff) * 0x100000001b3ULL;  // a separator: "ab","c" differs from "a","bc"
  }
  std::string hex() const {
    char s[17];
    std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(h_));
    return s;
  }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

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

RunResult result_from(json j) {
  static const json kDefault = RunResult{};
  for (auto& item : j.items()) {
    if (!item.value().is_string() || !kDefault.contains(item.key()) || !kDefault[item.key()].is_number_float()) continue;
    const std::string s = item.value().get<std::string>();
    const double inf = std::numeric_limits<double>::infinity();
    item.value() = s == "inf" ? inf : s == "-inf" ? -inf : std::numeric_limits<double>::quiet_NaN();
  }
  return j.get<RunResult>();
}

}  // namespace

std::string plan_fingerprint(const SweepSpec& spec, const std::vector<RunPlan>& plan) {
  Digest d;
  d.add("vines sweep plan " + std::to_string(kLogVersion));
  // Each study's settings, its scene file (wherever the sweep is started from) and the
  // scene as parsed (toml++ prints it in a fixed order).
  for (const StudySpec& st : spec.studies) {
    std::ostringstream scene;
    scene << read_scene_table(st.scene_path);
    const std::string where = std::filesystem::weakly_canonical(st.scene_path).string();
    for (const std::string& s : {st.name, where, st.group_by, st.optimize, scene.str()}) d.add(s);
    for (const KeyValue& v : st.set) d.add(v.key + "=" + v.label());
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
  std::size_t line_no = 0;
  for (std::size_t start = 0; start < text.size(); ++line_no) {
    const std::size_t nl = text.find('\n', start);
    const bool last = nl == std::string::npos || nl + 1 == text.size();
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
    // A run: its index and result; a torn last line is left out.
    try {
      if (nl == std::string::npos) throw std::runtime_error("no end of line");
      const json j = json::parse(line);
      const std::size_t i = j.at("run").get<std::size_t>();
      if (i >= runs) throw std::runtime_error("run " + std::to_string(i) + " is not in the plan");
      RunResult r = result_from(j.at("result"));
      r.done = true;
      out.finished += !out.results[i].done;
      out.results[i] = std::move(r);
    } catch (const std::exception& e) {
      if (!last) throw std::runtime_error(where + ": bad line in the log: " + e.what());
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
  const int flags = O_WRONLY | O_APPEND | O_CLOEXEC | (keep_bytes == 0 ? O_CREAT | O_TRUNC : 0);
  fd_ = ::open(file.c_str(), flags, 0644);
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
  const std::string line = json{{"run", run}, {"result", result_json(result)}}.dump() + '\n';
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
