#include "sim_host/hil/link/child.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <chrono>
#include <climits>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace vines::host {
namespace {

int ms(double s) { return s <= 0 ? 0 : static_cast<int>(std::min(s * 1e3 + 0.999, 1e9)); }

}  // namespace

std::string self_exe() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("cannot find this program's path (/proc/self/exe)");
  return std::string(buf, static_cast<std::size_t>(n));
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv) {
  int to_child[2], from_child[2];
  if (::pipe2(to_child, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  if (::pipe2(from_child, O_CLOEXEC) != 0) {
    ::close(to_child[0]);
    ::close(to_child[1]);
    throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  }
  std::vector<char*> cargv;
  for (const std::string& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  pid_ = ::fork();
  if (pid_ == 0) {
    ::dup2(to_child[0], 0);
    ::dup2(from_child[1], 1);
    ::execvp(cargv[0], cargv.data());
    _exit(127);
  }
  ::close(to_child[0]);
  ::close(from_child[1]);
  in_ = to_child[1];
  out_ = from_child[0];
  if (pid_ < 0) throw std::runtime_error(argv[0] + ": cannot start: " + std::strerror(errno));
  ::fcntl(in_, F_SETFL, O_NONBLOCK);
  ::fcntl(out_, F_SETFL, O_NONBLOCK);
  ::signal(SIGPIPE, SIG_IGN);  // a dead child shows as EPIPE, not a signal
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && status_ < 0) kill_now();
  if (in_ >= 0) ::close(in_);
  if (out_ >= 0) ::close(out_);
}

void ChildProcess::write_all(const std::uint8_t* p, std::size_t n, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (n > 0) {
    const ssize_t w = in_ >= 0 ? ::write(in_, p, n) : -1;
    if (w > 0) {
      p += w;
      n -= static_cast<std::size_t>(w);
      continue;
    }
    if (w < 0 && errno != EAGAIN && errno != EINTR)
      throw std::runtime_error(std::string("node: cannot write to it: ") + std::strerror(errno));
    const double left = std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
    if (left <= 0) throw std::runtime_error("node: not reading its input (write timed out)");
    pollfd pf{in_, POLLOUT, 0};
    ::poll(&pf, 1, ms(left));
  }
}

bool ChildProcess::read_some(std::vector<std::uint8_t>* out, double timeout_s) {
  if (out_ < 0) return false;
  pollfd pf{out_, POLLIN, 0};
  const double t = std::max(0.0, std::min(timeout_s, 1e6));
  timespec ts{static_cast<time_t>(t), static_cast<long>((t - std::floor(t)) * 1e9)};
  const int r = ::ppoll(&pf, 1, &ts, nullptr);
  if (r <= 0) return true;
  std::uint8_t buf[8192];
  for (;;) {
    const ssize_t n = ::read(out_, buf, sizeof buf);
    if (n > 0) {
      out->insert(out->end(), buf, buf + n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return true;
    ::close(out_);
    out_ = -1;
    return false;
  }
}

int ChildProcess::finish(double timeout_s) {
  if (status_ >= 0) return status_;
  if (in_ >= 0) {
    ::close(in_);
    in_ = -1;
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    int st = 0;
    if (::waitpid(pid_, &st, WNOHANG) == pid_) {
      status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
      return status_;
    }
    if (std::chrono::steady_clock::now() > end) {
      kill_now();
      return status_;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

void ChildProcess::kill_now() {
  if (pid_ <= 0 || status_ >= 0) return;
  ::kill(pid_, SIGKILL);
  int st = 0;
  ::waitpid(pid_, &st, 0);
  status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

}  // namespace vines::host
