// Deadline monitor of the sensor loop: each step's duration, measured on the
// port's counter, is held against a budget (normally one sensor period);
// steps over it are counted, the worst is kept. The loop reports both.
#pragma once

#include <cstdint>

namespace vines::hal {

class DeadlineMonitor {
 public:
  explicit DeadlineMonitor(std::uint32_t budget_ticks) : budget_(budget_ticks) {}

  // One step took `elapsed` counter ticks; true if it overran the budget.
  bool record(std::uint32_t elapsed) {
    if (elapsed > worst_) worst_ = elapsed;
    if (elapsed <= budget_) return false;
    ++overruns_;
    return true;
  }

  std::uint32_t budget() const { return budget_; }
  std::uint32_t overruns() const { return overruns_; }
  std::uint32_t worst() const { return worst_; }

 private:
  std::uint32_t budget_;
  std::uint32_t overruns_ = 0;
  std::uint32_t worst_ = 0;
};

}  // namespace vines::hal
