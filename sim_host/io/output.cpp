#include "sim_host/io/output.hpp"

#include <fcntl.h>
#include <fnmatch.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include <nlohmann/json.hpp>

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
  struct stat ls {}, st {};
  const bool present = ::lstat(path_.c_str(), &ls) == 0;
  const bool exists = ::stat(path_.c_str(), &st) == 0;  // the link's target, if a link
  // A link is never written through (someone else's file would be replaced),
  // unless it leads to a stream: /dev/stdout is a link to the process's fd 1.
  if (present && S_ISLNK(ls.st_mode) && (!exists || S_ISREG(st.st_mode) || S_ISDIR(st.st_mode)))
    throw std::runtime_error(path_ + ": cannot write: a symbolic link (vines writes no file through a link: "
                             "remove it or give another path)");
  // Not a regular file (/dev/stdout, a pipe, /dev/full): written in place, checked.
  if (exists && !S_ISREG(st.st_mode)) {
    file_ = std::fopen(path_.c_str(), "wb");
    if (file_ == nullptr) throw cannot_write(path_, errno);
    return;
  }
  // The temporary file in the target's folder (a rename stays on one file
  // system, and replaces the name: a link put there meanwhile, not its target).
  const fs::path target(path_);
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
  target_ = path_;
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
namespace {

// Up to five names, and how many more.
std::string name_list(std::vector<std::string> names) {
  std::sort(names.begin(), names.end());
  std::string list;
  for (std::size_t i = 0; i < names.size() && i < 5; ++i) list += (i ? ", " : "") + names[i];
  if (names.size() > 5) list += " and " + std::to_string(names.size() - 5) + " more";
  return list;
}

// A marker's text, read from its descriptor.
std::string read_marker(int fd) {
  std::string text;
  char buf[512];
  for (off_t at = 0;;) {
    const ssize_t n = ::pread(fd, buf, sizeof buf, at);
    if (n <= 0 || text.size() > 4096) break;
    text.append(buf, static_cast<std::size_t>(n));
    at += n;
  }
  return text;
}

}  // namespace

void create_folder(const std::string& dir) {
  std::error_code ec;
  const fs::path p(dir);
  if (fs::is_symlink(p, ec) && !fs::exists(p, ec))
    throw std::runtime_error(dir + ": cannot create: a symbolic link to " + fs::read_symlink(p, ec).string() +
                             ", which does not exist (remove the link, or make its target)");
  if (fs::exists(p, ec) && !fs::is_directory(p, ec))
    throw std::runtime_error(dir + ": cannot create: a file of that name exists");
  fs::create_directories(p, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create: " + ec.message());
}

OutputDir::OutputDir(std::string dir, std::string command, std::vector<std::string> owned, std::string fingerprint)
    : dir_(std::move(dir)), command_(std::move(command)), owned_(std::move(owned)) {
  if (dir_.empty()) throw std::runtime_error(command_ + ": the output folder is an empty path");
  create_folder(dir_);
  std::error_code ec;
  const std::string marker = file(kOutputMarker);
  struct stat ms {};
  const bool marked = ::lstat(marker.c_str(), &ms) == 0;
  if (marked && (!S_ISREG(ms.st_mode) || ms.st_nlink > 1))
    throw std::runtime_error(marker + ": not a file vines wrote (a link or a folder): refusing the folder");
  // No marker: vines did not make this folder, unless it is empty.
  if (!marked) {
    std::vector<std::string> present;
    for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().filename().string().rfind(std::string(kOutputMarker) + ".tmp-", 0) != 0)
        present.push_back(it->path().filename().string());  // (a marker's temporary file a kill left: ours)
    if (ec) throw std::runtime_error(dir_ + ": cannot read: " + ec.message());
    if (!present.empty())
      throw std::runtime_error(dir_ + ": holds files but no " + kOutputMarker + " marker, so no vines made it (" +
                               name_list(present) + "): give an empty or new folder");
  }
  lock_marker(!marked);
  try {
    refuse_foreign();
    // This command's marker: who writes the folder, from what.
    const std::string text = nlohmann::json{{"vines_output", 1},
                                            {"command", command_},
                                            {"fingerprint", fingerprint},
                                            {"pid", static_cast<long long>(::getpid())}}
                                 .dump() + '\n';
    if (::ftruncate(marker_fd_, 0) != 0 ||
        ::pwrite(marker_fd_, text.data(), text.size(), 0) != static_cast<ssize_t>(text.size()))
      throw cannot_write(marker, errno);
  } catch (...) {
    ::close(marker_fd_);
    marker_fd_ = -1;
    throw;
  }
}

OutputDir::~OutputDir() {
  if (marker_fd_ >= 0) ::close(marker_fd_);  // the lock goes with it
}

// The marker, locked: a new one is written whole in a temporary file and
// linked in place (two commands on a new folder: one links it, the other
// finds it locked); an existing one must be this command's.
void OutputDir::lock_marker(bool fresh) {
  const std::string marker = file(kOutputMarker);
  if (fresh) {
    std::string tmpl = file(std::string(kOutputMarker) + ".tmp-XXXXXX");
    const int fd = ::mkstemp(tmpl.data());
    if (fd < 0) throw cannot_write(marker, errno);
    const std::string text = nlohmann::json{{"vines_output", 1}, {"command", command_},
                                            {"pid", static_cast<long long>(::getpid())}}.dump() + '\n';
    const bool ok = ::flock(fd, LOCK_EX | LOCK_NB) == 0 && ::fchmod(fd, new_file_mode()) == 0 &&
                    ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) &&
                    ::link(tmpl.c_str(), marker.c_str()) == 0;
    const int err = errno;
    ::unlink(tmpl.c_str());
    if (ok) {
      marker_fd_ = fd;
      return;
    }
    ::close(fd);
    if (err != EEXIST) throw cannot_write(marker, err);
  }
  marker_fd_ = ::open(marker.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
  if (marker_fd_ < 0) throw std::runtime_error(marker + ": cannot open: " + std::strerror(errno));
  const std::string text = read_marker(marker_fd_);
  const nlohmann::json m = nlohmann::json::parse(text, nullptr, false);
  const bool valid = m.is_object() && m.value("vines_output", 0) == 1 && m.contains("command") &&
                     m["command"].is_string();
  const std::string owner = valid ? m["command"].get<std::string>() : "";
  if (::flock(marker_fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(marker_fd_);
    marker_fd_ = -1;
    if (err != EWOULDBLOCK) throw std::runtime_error(marker + ": cannot lock: " + std::strerror(err));
    const std::string pid = valid && m.contains("pid") ? " (process " + m["pid"].dump() + ")" : "";
    throw std::runtime_error(dir_ + ": in use by " + (valid ? owner : std::string("another vines")) + pid +
                             ": wait for it to end, or give another folder");
  }
  if (!valid || owner != command_) {
    ::close(marker_fd_);
    marker_fd_ = -1;
    throw std::runtime_error(dir_ + ": " + (valid ? owner + "'s folder, not " + command_ + "'s"
                                                  : std::string(kOutputMarker) + " is not a vines marker") +
                             ": give another folder");
  }
}

// Anything the command does not write, or any link, is someone else's: the
// folder is refused (lstat: a link named like an output is a link).
void OutputDir::refuse_foreign() const {
  std::error_code ec;
  std::vector<std::string> foreign;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    struct stat st {};
    if (::lstat(it->path().c_str(), &st) != 0) continue;  // gone meanwhile
    // A hard link's other names are outside the folder: written in place
    // (the sweep's log is appended to), it would change them too.
    const bool linked = S_ISREG(st.st_mode) && st.st_nlink > 1;
    if (S_ISLNK(st.st_mode)) foreign.push_back(name + " (a link)");
    else if (S_ISDIR(st.st_mode)) foreign.push_back(name + "/");
    else if (linked) foreign.push_back(name + " (a hard link)");
    else if (name != kOutputMarker && (!owns(name) || !S_ISREG(st.st_mode))) foreign.push_back(name);
  }
  if (ec) throw std::runtime_error(dir_ + ": cannot read: " + ec.message());
  if (foreign.empty()) return;
  throw std::runtime_error(dir_ + ": holds files " + command_ + " does not write (" + name_list(foreign) +
                           "): give an empty or new folder, or one of " + command_ + "'s own");
}

std::string OutputDir::file(const std::string& name) const { return (fs::path(dir_) / name).string(); }

void OutputDir::finish(const std::vector<std::string>& written) const {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name != kOutputMarker && owns(name) && std::find(written.begin(), written.end(), name) == written.end())
      stale.push_back(it->path());
  }
  if (ec) throw std::runtime_error(dir_ + ": cannot read: " + ec.message());
  for (const fs::path& p : stale)
    if (!fs::remove(p, ec) && ec) throw std::runtime_error(p.string() + ": cannot remove: " + ec.message());
}

bool OutputDir::owns(const std::string& name) const {
  if (name.rfind(std::string(kOutputMarker) + ".tmp-", 0) == 0) return true;  // a marker being made
  // A temporary file an interrupted write of this command left behind.
  const std::size_t tmp = name.rfind(".tmp-");
  if (name.size() > 1 && name[0] == '.' && tmp != std::string::npos) return owns(name.substr(1, tmp - 1));
  for (const std::string& pattern : owned_)
    if (::fnmatch(pattern.c_str(), name.c_str(), FNM_PERIOD) == 0) return true;
  return false;
}

}  // namespace vines::host
