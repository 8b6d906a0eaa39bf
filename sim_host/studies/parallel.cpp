#include "sim_host/studies/parallel.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>
#include <unistd.h>

namespace vines::host {
namespace {

// Progress of a map on stderr: a bar redrawn in place on a TTY, else a line
// every tenth of the jobs; elapsed time and an estimate of what is left.
class Progress {
 public:
  Progress(std::size_t total, const MapOptions& opt)
      : total_(total), opt_(opt), tty_(opt.progress && isatty(fileno(stderr))),
        every_(std::max<std::size_t>(1, total / (tty_ ? 200 : 10))) {}

  void finished_one() {
    const std::size_t done = ++done_;
    if (opt_.progress && !announced_.load() && elapsed() >= kAnnounceAfter_s) announce(done);
    if (opt_.progress && (done % every_ == 0 || done == total_)) report(done);
  }

 private:
  static constexpr double kAnnounceAfter_s = 2.0;

  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

  // Once, a few seconds in: the size of a map that will take over a minute,
  // and the time it will take at the rate so far.
  void announce(std::size_t done) {
    if (announced_.exchange(true)) return;
    const double el = elapsed(), eta = el / static_cast<double>(done) * static_cast<double>(total_ - done);
    if (eta < 60) return;
    std::lock_guard<std::mutex> lock(mutex_);
    std::fprintf(stderr, "%s%s: %zu %s in all, about %.0f min more at the rate of the first %.0f s "
                 "(Ctrl-C stops)\n", tty_ ? "\n" : "", opt_.label.c_str(), total_, opt_.unit.c_str(), eta / 60, el);
  }

  void report(std::size_t done) {
    const double el = elapsed();
    const double eta = el / static_cast<double>(done) * static_cast<double>(total_ - done);
    std::lock_guard<std::mutex> lock(mutex_);
    if (tty_) {
      const int width = 30, fill = static_cast<int>(width * done / total_);
      std::fprintf(stderr, "\r[%s%s] %zu/%zu  %.1f s elapsed, ETA %.1f s ", std::string(fill, '#').c_str(),
                   std::string(width - fill, '.').c_str(), done, total_, el, eta);
      if (done == total_) std::fputc('\n', stderr);
    } else {
      std::fprintf(stderr, "%s: %zu/%zu %s, %.1f s elapsed, ETA %.1f s\n", opt_.label.c_str(), done, total_,
                   opt_.unit.c_str(), el, eta);
    }
  }

  const std::size_t total_;
  const MapOptions& opt_;
  const bool tty_;
  const std::size_t every_;
  const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  std::atomic<std::size_t> done_{0};
  std::atomic<bool> announced_{false};
  std::mutex mutex_;
};

}  // namespace

int map_threads(int requested) {
  return requested > 0 ? requested : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void parallel_map(std::size_t n, const MapOptions& opt, const std::function<void(std::size_t)>& job) {
  if (n == 0) return;
  Progress progress(n, opt);
  // One job per task (jobs are whole runs: no grouping), in an arena of the
  // requested size; a stop cancels the jobs not yet started.
  tbb::task_group_context context;
  tbb::task_arena arena(map_threads(opt.threads));
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (opt.stop != nullptr && opt.stop->load()) {
              context.cancel_group_execution();
              return;
            }
            try {
              job(i);
            } catch (const Stopped&) {
              context.cancel_group_execution();
              return;
            }
            progress.finished_one();
          }
        },
        tbb::simple_partitioner(), context);
  });
}

}  // namespace vines::host
