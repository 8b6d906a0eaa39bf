// How the commands write their results: every write checked and atomic, none
// through a link, every output folder marked, locked and owned by the command
// that writes it, folder names made safe.
//
// - AtomicFile: the bytes go to a temporary file beside the target
//   (.NAME.tmp-XXXXXX); commit() flushes it to disk and renames it over the
//   target's name, so the target is either the old file or the new one in
//   full, never a truncated mix. A symbolic link at the target is refused
//   (a link to a stream, /dev/stdout or a pipe, is written in place, checked).
//   Any failure throws "PATH: cannot write: <reason>".
// - OutputDir: a command's output folder. Its marker, DIR/.vines-output
//   (the command, a fingerprint of its inputs, the process), says vines
//   made it: a folder with files and no marker, or another command's, is
//   refused; so is any link or foreign entry in it (named). The marker is
//   locked (flock) while the command lives: a second command on the folder
//   is refused, naming the holder. finish() removes the command's own files
//   this run did not write (a timeseries.csv of an earlier run beside a
//   summary.json without one).
// - create_folder: a folder and its parents made, or a refusal that says why
//   (a file of that name, a symbolic link whose target does not exist).
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

// Makes `dir` and its parents; throws "DIR: cannot create: <why>".
void create_folder(const std::string& dir);

// The marker's name in every output folder.
inline constexpr const char* kOutputMarker = ".vines-output";

class OutputDir {
 public:
  // Claims `dir` for `command` (e.g. "vines run"), whose files are `owned`
  // (names, or fnmatch patterns such as "case_*.toml"), and holds its lock
  // until destroyed. `fingerprint`: what the outputs come from (a scene's or
  // spec's digest), kept in the marker. Throws on an empty path, a folder
  // that cannot be created (with the reason), a folder in use by another
  // vines (its command and process named), a folder another command or no
  // vines made, a folder that holds links or other files or folders (named).
  // Temporary files an interrupted write left (.NAME.tmp-*) count as the
  // command's.
  OutputDir(std::string dir, std::string command, std::vector<std::string> owned, std::string fingerprint = "");
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  std::string file(const std::string& name) const;  // DIR/NAME
  // After a run: removes the owned files not in `written` (and left temporary files).
  void finish(const std::vector<std::string>& written) const;

 private:
  bool owns(const std::string& name) const;
  void lock_marker(bool fresh);
  void refuse_foreign() const;

  std::string dir_, command_;
  std::vector<std::string> owned_;
  int marker_fd_ = -1;
};

}  // namespace vines::host
