// The HilWatch of `vines hil --serve`: the bench's samples as the page's
// series (rows.hpp), decimated into frames (decimator.hpp), published to the
// hub (hub.hpp); at the end the report and an `end` event. On the bench's
// thread: it formats a frame every few samples and never waits.
#pragma once

#include <memory>
#include <vector>

#include "sim_host/hil/watch.hpp"
#include "sim_host/monitor/decimator.hpp"
#include "sim_host/monitor/hub.hpp"
#include "sim_host/monitor/rows.hpp"

namespace vines::host::monitor {

// Kept samples per frame.
inline constexpr int kFrameSamples = 20;

class PageWatch : public HilWatch {
 public:
  explicit PageWatch(Hub& hub) : hub_(hub) {}
  void start(const Bench& b) override;
  void step(long long k, const HilRecord& rec) override;
  void finish(const HilReport& r) override;

 private:
  Hub& hub_;
  std::unique_ptr<BenchRows> rows_;
  std::unique_ptr<Decimator> dec_;
  std::vector<double> row_;
  std::string event_;
};

}  // namespace vines::host::monitor
