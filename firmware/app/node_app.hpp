// The firmware application around the link node (vines/link/node.hpp), on
// the HAL port facade (vines/hal/port.hpp): the same source on the board
// (node_main.cpp over the CMSDK UART) and on the host (`vines node` over
// stdin/stdout). It
//   - feeds the node every byte of the link, with the local clock in real
//     time (lock step: the frames' stamps are the clock);
//   - times each step of the model on the port's counter, interrupts masked,
//     and holds it against the budget (the deadline monitor, whose counts
//     the node sends in every STATUS and each step's ticks in TELEMETRY);
//   - ends after STOP (0), at the end of the link (0), when the link breaks
//     or stays silent for the idle limit (1, with a message on the console).
#pragma once

#include <cstddef>
#include <cstdint>

#include "vines/hal/deadline.hpp"
#include "vines/hal/port.hpp"
#include "vines/link/config.hpp"
#include "vines/link/messages.hpp"
#include "vines/link/node.hpp"

namespace vines::app {

// A node's Plant that times another one.
template <class Plant>
class TimedPlant {
 public:
  explicit TimedPlant(Plant* p) : p_(p) {}

  const char* image_begin(std::uint32_t total) { return p_->image_begin(total); }
  const char* image_push(const std::uint8_t* b, std::size_t n) { return p_->image_push(b, n); }
  const char* image_finish() { return p_->image_finish(); }

  bool configure(const link::NodeConfig& c, char* msg, std::size_t cap) {
    if (!p_->configure(c, msg, cap)) return false;
    const double period = static_cast<double>(hal::counter_hz()) / c.scene.loop.sensor_rate_hz;
    budget_ = c.budget_ticks ? c.budget_ticks
                             : static_cast<std::uint32_t>(period < 4e9 ? period + 0.5 : 4e9);
    monitor_ = hal::DeadlineMonitor(budget_);
    return true;
  }

  void sense(const double* y, int ny) { p_->sense(y, ny); }
  void init(double a0, double f0) {
    monitor_ = hal::DeadlineMonitor(budget_);
    worst_k_ = 0;
    const std::uint32_t t0 = start();
    p_->init(a0, f0);
    stop(t0);
  }
  void step(double a1, double f1) {
    const std::uint32_t t0 = start();
    p_->step(a1, f1);
    stop(t0);
  }

  // t->k is set by the node before it reads.
  void read(link::Telemetry* t) {
    p_->read(t);
    t->step_ticks = last_;
    if (new_worst_) worst_k_ = t->k;
    new_worst_ = false;
  }

  void timing(link::StepTiming* s) const {
    s->counter_hz = hal::counter_hz();
    s->budget_ticks = budget_;
    s->overruns = monitor_.overruns();
    s->worst_ticks = monitor_.worst();
    s->worst_k = worst_k_;
    s->stack_peak_bytes = hal::stack_peak_bytes();
  }

 private:
  static std::uint32_t start() {
    hal::irq_off();
    return hal::counter_now();
  }
  void stop(std::uint32_t t0) {
    last_ = hal::counter_now() - t0;
    hal::irq_on();
    new_worst_ = last_ > monitor_.worst();
    monitor_.record(last_);
  }

  Plant* p_;
  std::uint32_t budget_ = 0xFFFFFFFFu, last_ = 0, worst_k_ = 0;
  bool new_worst_ = false;
  hal::DeadlineMonitor monitor_{0xFFFFFFFFu};
};

// The node's output: the link.
struct PortSink {
  bool broken = false;
  void write(const std::uint8_t* p, std::size_t n) {
    if (!broken && !hal::link_write(p, n)) broken = true;
  }
};

struct ServeOptions {
  bool realtime = false;               // deadlines on the local clock
  std::uint32_t idle_limit_ms = 30000; // no byte for this long: give up
};

// Runs the node until the run ends; the application's exit status.
template <class Plant>
int serve(link::Node<Plant, PortSink>& node, const PortSink& sink, const ServeOptions& o) {
  std::uint64_t last_byte = hal::time_ns();
  while (!sink.broken) {
    std::uint32_t wait_ms = 100;
    if (o.realtime) {
      const std::uint64_t next = node.next_deadline_local(), now = hal::time_ns();
      if (next != UINT64_MAX) wait_ms = next <= now ? 0u : static_cast<std::uint32_t>(
                                                              (next - now) / 1000000u < 100u ? (next - now) / 1000000u + 1 : 100u);
    }
    const int b = hal::link_getc(wait_ms);
    const std::uint64_t now = hal::time_ns();
    if (b == hal::kLinkClosed) return 0;  // the bench is done
    if (b >= 0) {
      last_byte = now;
      node.on_byte(static_cast<std::uint8_t>(b), o.realtime ? now : 0);
      if (node.stopped()) return 0;
    } else if (now - last_byte > std::uint64_t{o.idle_limit_ms} * 1000000u) {
      hal::console_write("vines node: no input within the idle limit\n");
      return 1;
    }
    if (o.realtime) node.poll(hal::time_ns());
  }
  hal::console_write("vines node: the link broke: ");
  hal::console_write(hal::port_error());
  hal::console_write("\n");
  return 1;
}

// A board's main(): the stack painted for its high-water mark, the port
// opened, a status sent unasked (the bench waits for it: what it sent
// before the UART was on is lost), the node served in lock step until STOP
// (0) or 10 s of silence (1).
template <class Plant>
int board_main(link::Node<Plant, PortSink>& node, const PortSink& sink) {
  hal::stack_paint();
  hal::port_init();
  node.announce();
  ServeOptions o;
  o.idle_limit_ms = 10000;
  return serve(node, sink, o);
}

}  // namespace vines::app
