#include "sim_host/monitor/watch.hpp"

namespace vines::host::monitor {

void PageWatch::start(const Bench& b) {
  rows_ = std::make_unique<BenchRows>(b);
  const PageMeta& m = rows_->meta();
  dec_ = std::make_unique<Decimator>(m.every, kFrameSamples, m.series.size());
  hub_.set_header(sse_event("meta", to_json(m).dump()));
}

void PageWatch::step(long long k, const HilRecord& rec) {
  // Every sample updates what is held (the twin's factors), kept or not.
  rows_->take(k, rec, &row_);
  if (dec_->keeps(k, rows_->event(row_)) && dec_->add(k, row_, &event_)) hub_.publish(std::move(event_));
}

void PageWatch::finish(const HilReport& r) {
  if (dec_ && dec_->flush(&event_)) hub_.publish(std::move(event_));
  hub_.publish(sse_event("report", to_json(r).dump()));
  hub_.publish(sse_event("end", "{}"));
  hub_.close();
}

}  // namespace vines::host::monitor
