// Kept samples into frames: every Mth sample of the record (by its index, so
// a live run and its --csv keep the same ones) and every event sample (a VI
// NES contact: an impact lasts a few ms, which every 5th sample would cut to
// one or two points and miss its peak), their values as they are
// (no filter: the page shows the run's numbers), a frame of F kept samples
// as one Server-Sent Event whose data is {"k": [...], "v": [[series 0], ...]}
// (non-finite values as null).
#pragma once

#include <string>
#include <vector>

namespace vines::host::monitor {

// One Server-Sent Event: "event: NAME\ndata: DATA\n\n" (DATA on one line).
std::string sse_event(const std::string& name, const std::string& data);

class Decimator {
 public:
  // every >= 1, per_frame >= 1; width: the series' count.
  Decimator(int every, int per_frame, std::size_t width);
  // Whether sample k goes to the page: on the grid or an event, and after
  // the last one kept (a sample again after a restart, or late, is not sent
  // twice).
  bool keeps(long long k, bool event = false) const { return (event || k % every_ == 0) && k > last_; }
  // Kept sample k's values; true with the frame's event in *event when the
  // frame is full.
  bool add(long long k, const std::vector<double>& v, std::string* event);
  // The kept samples not sent yet as an event; false if none.
  bool flush(std::string* event);

 private:
  const int every_, per_frame_;
  long long last_ = -1;
  std::vector<long long> k_;
  std::vector<std::vector<double>> v_;  // by series
};

}  // namespace vines::host::monitor
