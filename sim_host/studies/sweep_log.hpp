// DIR/runs.jsonl of `vines sweep`: every finished run, appended as it
// finishes, so that a second Ctrl-C, a kill or a power cut loses nothing that
// finished (at most the last ~0.2 s of rows on a power cut), and
// `vines sweep --resume DIR` runs only what is missing.
//
// Line 1: {"vines_sweep_log": 2, "spec": PATH, "fingerprint": HEX, "runs": N}
// Then one line per finished run, in the order they finished:
//   {"run": INDEX, "result": RunResult as JSON, "check": HEX}
// check: the digest (digest.hpp) of the line's text before it. Non-finite
// numbers of a result are written as "nan", "inf", "-inf". The fingerprint
// covers the spec, its scenes, every record's bytes, the plan and vines'
// version: a resume proves its log is this sweep's, line by line.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "sim_host/studies/sweep.hpp"

namespace vines::host {

// A digest of everything a sweep's results depend on that a resumed sweep
// must share: the spec's studies, their scene files and the plan.
std::string plan_fingerprint(const SweepSpec& spec, const std::vector<RunPlan>& plan);

// A run's line of the log from the JSON text of {"run": I, "result": {...}}:
// its check appended, and the end of line.
std::string checked_log_line(const std::string& json_text);

// A log read back: the finished runs by plan index (others not done), the
// bytes of whole valid lines, and a warning when a torn last line was left out.
struct SweepLogContents {
  std::vector<RunResult> results;
  std::size_t finished = 0;
  std::size_t good_bytes = 0;
  std::string warning;
};

// Reads `file`; refuses (std::runtime_error naming the file and line) a log
// of another spec, plan, record or vines (fingerprint, run count), or with a
// bad line: a check that does not match, a run index outside the plan or
// seen before, a result with a member missing, unknown or of the wrong
// type, or not finished. A last line without its end of line (a write torn
// by a power cut) is left out with a warning.
SweepLogContents read_sweep_log(const std::string& file, const std::string& fingerprint, std::size_t runs);

// The writer: append() from any thread; each row is one write(2) of a whole
// line; a thread syncs the file to disk (fdatasync) every 0.2 s while rows
// come in, and close() syncs the end. A failed write or sync throws with the
// path and the system's reason.
class SweepLog {
 public:
  // A new log with its header line, or (keep_bytes > 0) an existing one cut
  // to keep_bytes (its valid lines) to append to.
  SweepLog(const std::string& file, const std::string& spec, const std::string& fingerprint, std::size_t runs,
           std::size_t keep_bytes);
  ~SweepLog();
  SweepLog(const SweepLog&) = delete;
  SweepLog& operator=(const SweepLog&) = delete;

  void append(std::size_t run, const RunResult& result);
  void close();  // the final sync; checked

 private:
  void write_line(const std::string& line);
  void sync_loop();
  [[noreturn]] void fail(const std::string& what, int err) const;

  std::string file_;
  int fd_ = -1;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool dirty_ = false, closing_ = false;
  int sync_error_ = 0;  // errno of a failed background sync, thrown by the next append/close
  std::thread syncer_;
};

}  // namespace vines::host
