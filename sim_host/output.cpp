#include "sim_host/output.hpp"

#include <fcntl.h>
#include <fnmatch.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace vines::host {

namespace fs = std::filesystem;

namespace {

// The mode a new file gets from open(): 0666 less the umask (read once).
mode_t new_file_mode() {
  static const mode_t mode = [] {
    const mode_t mask = ::umask(0);
    ::umask(mask);
    return 0666 & ~mask;
  }();
  return mode;
}

std::runtime_error cannot_write(const std::string& path, int err) {
  return std::runtime_error(path + ": cannot write: " + std::strerror(err));
}

}  // namespace

// ---- AtomicFile ----
AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  // A symbolic link is followed: the file it names is replaced, the link stays.
  fs::path target(path_);
  std::error_code ec;
  if (fs::is_symlink(target, ec)) {
    const fs::path resolved = fs::canonical(target, ec);
    if (!ec) target = resolved;
  }
  // Not a regular file (/dev/stdout, a pipe, /dev/full): written in place, checked.
  struct stat st {};
  const bool exists = ::stat(target.c_str(), &st) == 0;
  if (exists && !S_ISREG(st.st_mode)) {
    file_ = std::fopen(target.c_str(), "wb");
    if (file_ == nullptr) throw cannot_write(path_, errno);
    return;
  }
  // The temporary file in the target's folder (a rename stays on one file system).
  std::string tmpl = (target.parent_path() / ("." + target.filename().string() + ".tmp-XXXXXX")).string();
  const int fd = ::mkstemp(tmpl.data());
  if (fd < 0) throw cannot_write(path_, errno);
  tmp_ = tmpl;
  // The replaced file's mode, or a new file's (mkstemp's 0600 would hide the result).
  ::fchmod(fd, exists ? st.st_mode & 07777 : new_file_mode());
  file_ = ::fdopen(fd, "wb");
  if (file_ == nullptr) {
    const int err = errno;
    ::close(fd);
    fail(err);
  }
  target_ = target.string();
}

AtomicFile::~AtomicFile() {
  // Not committed (an exception in flight, or an early return): the target stays as it was.
  if (file_ != nullptr) std::fclose(file_);
  if (!tmp_.empty()) ::unlink(tmp_.c_str());
}

void AtomicFile::write(const char* data, std::size_t n) {
  if (file_ == nullptr) throw std::logic_error(path_ + ": written after commit");
  if (std::fwrite(data, 1, n, file_) != n) fail(errno);
}

void AtomicFile::commit() {
  if (file_ == nullptr) throw std::logic_error(path_ + ": committed twice");
  // Everything on disk (a full disk shows at the flush or the close), then in place.
  if (std::fflush(file_) != 0) fail(errno);
  if (!tmp_.empty() && ::fsync(::fileno(file_)) != 0) fail(errno);
  const int closed = std::fclose(file_);
  file_ = nullptr;
  if (closed != 0) fail(errno);
  if (tmp_.empty()) return;
  if (std::rename(tmp_.c_str(), target_.c_str()) != 0) fail(errno);
  tmp_.clear();
}

void AtomicFile::fail(int err) {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
  if (!tmp_.empty()) ::unlink(tmp_.c_str());
  tmp_.clear();
  throw cannot_write(path_, err);
}

void write_file_atomic(const std::string& path, const std::string& text) {
  AtomicFile f(path);
  f.write(text);
  f.commit();
}

// ---- names ----
std::string safe_file_name(const std::string& name) {
  constexpr std::size_t kMaxBytes = 100;
  std::string s = name.substr(0, kMaxBytes);
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) c = '_';
  for (char& c : s) {
    if (c != '.') break;
    c = '_';
  }
  return s.empty() ? "_" : s;
}

// ---- OutputDir ----
OutputDir::OutputDir(std::string dir, std::string command, std::vector<std::string> owned)
    : dir_(std::move(dir)), command_(std::move(command)), owned_(std::move(owned)) {
  if (dir_.empty()) throw std::runtime_error(command_ + ": the output folder is an empty path");
  std::error_code ec;
  if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
    throw std::runtime_error(dir_ + ": cannot create: a file of that name exists");
  fs::create_directories(dir_, ec);
  if (ec) throw std::runtime_error(dir_ + ": cannot create: " + ec.message());
  // Anything the command does not write is someone else's: the folder is refused.
  std::vector<std::string> foreign;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!owns(name) || !it->is_regular_file()) foreign.push_back(name + (it->is_directory() ? "/" : ""));
  }
  if (ec) throw std::runtime_error(dir_ + ": cannot read: " + ec.message());
  if (foreign.empty()) return;
  std::sort(foreign.begin(), foreign.end());
  std::string list;
  for (std::size_t i = 0; i < foreign.size() && i < 5; ++i) list += (i ? ", " : "") + foreign[i];
  if (foreign.size() > 5) list += " and " + std::to_string(foreign.size() - 5) + " more";
  throw std::runtime_error(dir_ + ": holds files " + command_ + " does not write (" + list +
                           "): give an empty or new folder, or one of " + command_ + "'s own");
}

std::string OutputDir::file(const std::string& name) const { return (fs::path(dir_) / name).string(); }

void OutputDir::finish(const std::vector<std::string>& written) const {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (owns(name) && std::find(written.begin(), written.end(), name) == written.end()) stale.push_back(it->path());
  }
  if (ec) throw std::runtime_error(dir_ + ": cannot read: " + ec.message());
  for (const fs::path& p : stale)
    if (!fs::remove(p, ec) && ec) throw std::runtime_error(p.string() + ": cannot remove: " + ec.message());
}

bool OutputDir::owns(const std::string& name) const {
  // A temporary file an interrupted write of this command left behind.
  const std::size_t tmp = name.rfind(".tmp-");
  if (name.size() > 1 && name[0] == '.' && tmp != std::string::npos) return owns(name.substr(1, tmp - 1));
  for (const std::string& pattern : owned_)
    if (::fnmatch(pattern.c_str(), name.c_str(), FNM_PERIOD) == 0) return true;
  return false;
}

}  // namespace vines::host
