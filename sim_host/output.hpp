// How the commands write their results: every write checked and atomic, every
// output folder owned by the command that writes it, folder names made safe.
//
// - AtomicFile: the bytes go to a temporary file beside the target
//   (.NAME.tmp-XXXXXX); commit() flushes it to disk and renames it over the
//   target, so the target is either the old file or the new one in full, never
//   a truncated mix. Any failure throws "PATH: cannot write: <reason>".
// - OutputDir: a command's output folder. Claiming it refuses a folder that
//   holds anything the command does not write (naming it) and creates the
//   folder; finish() removes the command's own files this run did not write
//   (a timeseries.csv of an earlier run beside a summary.json without one).
// - safe_file_name: a scene or spec name reduced to one safe path component.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace vines::host {

class AtomicFile {
 public:
  explicit AtomicFile(std::string path);  // creates the temporary file
  ~AtomicFile();                          // not committed: the temporary file is removed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  void write(const char* data, std::size_t n);
  void write(const std::string& s) { write(s.data(), s.size()); }
  // Flushes, syncs and closes the temporary file, then renames it over the target.
  void commit();

 private:
  [[noreturn]] void fail(int err);  // removes the temporary file and throws

  std::string path_;    // as given (in messages)
  std::string target_;  // the file replaced (a link followed); "" when written in place
  std::string tmp_;     // the temporary file until it is renamed
  std::FILE* file_ = nullptr;
};

// The whole of `text` to `path`, atomically.
void write_file_atomic(const std::string& path, const std::string& text);

// Keeps [A-Za-z0-9._-], every other byte becomes '_'; leading dots become '_'
// (so never "." or ".." or hidden); "" becomes "_"; at most 100 bytes.
std::string safe_file_name(const std::string& name);

class OutputDir {
 public:
  // Claims `dir` for `command` (e.g. "vines run"), whose files are `owned`
  // (names, or fnmatch patterns such as "case_*.toml"). Throws on an empty
  // path, a folder that cannot be created (with the reason), or a folder that
  // holds other files or folders (named). Temporary files an interrupted write
  // left (.NAME.tmp-*) count as the command's.
  OutputDir(std::string dir, std::string command, std::vector<std::string> owned);
  std::string file(const std::string& name) const;  // DIR/NAME
  // After a run: removes the owned files not in `written` (and left temporary files).
  void finish(const std::vector<std::string>& written) const;

 private:
  bool owns(const std::string& name) const;

  std::string dir_, command_;
  std::vector<std::string> owned_;
};

}  // namespace vines::host
