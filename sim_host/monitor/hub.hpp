// The run's events for the page's clients: one log (the history) that the
// bench appends to, and each client a cursor in it, so that a client costs
// the bench nothing. A page opened late reads the history from its start; a
// client that reads more slowly than the run falls out of the history (which
// is bounded in bytes) and is dropped; one that stops reading is dropped by
// the server (its socket's write timeout): the bench never waits.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace vines::host::monitor {

using Event = std::shared_ptr<const std::string>;

struct HubLimits {
  int max_clients = 4;
  std::size_t history_bytes = std::size_t{64} << 20;
};

class Hub {
 public:
  explicit Hub(HubLimits limits = {}) : limits_(limits) {}

  // Bench side. The event every client reads first (the page's series), set
  // once, before or after clients join.
  void set_header(std::string event);
  // Appends an event. Never waits: if a server thread holds the lock, the
  // event waits in the bench's own list for the next publish (or close).
  void publish(std::string event);
  // The last events in (this one waits for the lock); no more after.
  void close();

  // Server side. A new client's cursor (before the header), or none when
  // max_clients are connected already.
  std::optional<long long> join();
  void leave();
  // What next() found: events, none within the wait, the end (the hub closed
  // and the client has every event), or the client fell out of the history
  // (dropped).
  enum class Next { kEvents, kIdle, kEnd, kBehind };
  // The events from *cursor on into *out (replacing its contents), *cursor
  // moved past them; waits up to `wait` for one.
  Next next(long long* cursor, std::vector<Event>* out, std::chrono::milliseconds wait);
  // Counts a client dropped by the server (its socket blocked).
  void count_dropped();
  // Waits up to `wait` for a change (the header set, events in, the hub
  // closed) past `seen` (a value this returned before; 0 at first); returns
  // the hub's changes so far.
  long long wait_for_change(long long seen, std::chrono::milliseconds wait);
  // Waits up to `wait` for every client to leave; true if they did.
  bool wait_until_no_clients(std::chrono::milliseconds wait);
  // Waits up to `wait` for a client to have read every event to the end
  // and every client to have left; true if so.
  bool wait_until_read(std::chrono::milliseconds wait);

  int clients() const;
  const HubLimits& limits() const { return limits_; }
  long long dropped() const;
  long long published() const;

 private:
  // Moves the bench's pending events into the log; the lock held.
  void append_pending();

  const HubLimits limits_;
  mutable std::mutex m_;
  std::condition_variable cv_;
  Event header_;
  std::deque<Event> log_;
  long long first_ = 0;  // the index of log_.front()
  std::size_t bytes_ = 0;
  bool closed_ = false;
  int clients_ = 0;
  int finished_ = 0;  // clients that read to the end
  long long dropped_ = 0;
  long long changes_ = 0;  // set_header, append_pending with events, close
  std::vector<std::string> pending_;  // the bench's only: waiting for the lock
};

}  // namespace vines::host::monitor
