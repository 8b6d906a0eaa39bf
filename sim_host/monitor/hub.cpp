#include "sim_host/monitor/hub.hpp"

#include <utility>

namespace vines::host::monitor {

void Hub::set_header(std::string event) {
  {
    std::lock_guard<std::mutex> lock(m_);
    header_ = std::make_shared<const std::string>(std::move(event));
    ++changes_;
  }
  cv_.notify_all();
}

void Hub::append_pending() {
  if (!pending_.empty()) ++changes_;
  for (std::string& e : pending_) {
    bytes_ += e.size();
    log_.push_back(std::make_shared<const std::string>(std::move(e)));
  }
  pending_.clear();
  // The oldest events go once the history is over its bound (the newest stays).
  while (bytes_ > limits_.history_bytes && log_.size() > 1) {
    bytes_ -= log_.front()->size();
    log_.pop_front();
    ++first_;
  }
}

void Hub::publish(std::string event) {
  pending_.push_back(std::move(event));
  std::unique_lock<std::mutex> lock(m_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  append_pending();
  lock.unlock();
  cv_.notify_all();
}

void Hub::close() {
  {
    std::lock_guard<std::mutex> lock(m_);
    append_pending();
    closed_ = true;
    ++changes_;
  }
  cv_.notify_all();
}

std::optional<long long> Hub::join() {
  std::lock_guard<std::mutex> lock(m_);
  if (clients_ >= limits_.max_clients) return std::nullopt;
  ++clients_;
  return -1 - first_;  // before the header; the history from its start after it
}

void Hub::leave() {
  {
    std::lock_guard<std::mutex> lock(m_);
    --clients_;
  }
  cv_.notify_all();
}

Hub::Next Hub::next(long long* cursor, std::vector<Event>* out, std::chrono::milliseconds wait) {
  out->clear();
  std::unique_lock<std::mutex> lock(m_);
  // A cursor below zero has not had the header: -1 - c, the history from c.
  const auto ready = [&] {
    if (*cursor < 0) return header_ != nullptr || closed_;
    return closed_ || *cursor < first_ + static_cast<long long>(log_.size());
  };
  if (!cv_.wait_for(lock, wait, ready)) return Next::kIdle;
  if (*cursor < 0) {
    if (header_) out->push_back(header_);
    *cursor = -1 - *cursor;
  }
  if (*cursor < first_) return Next::kBehind;
  for (auto i = static_cast<std::size_t>(*cursor - first_); i < log_.size(); ++i) out->push_back(log_[i]);
  *cursor = first_ + static_cast<long long>(log_.size());
  if (out->empty() && closed_) {
    ++finished_;
    lock.unlock();
    cv_.notify_all();
    return Next::kEnd;
  }
  return Next::kEvents;
}

void Hub::count_dropped() {
  std::lock_guard<std::mutex> lock(m_);
  ++dropped_;
}

long long Hub::wait_for_change(long long seen, std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait_for(lock, wait, [&] { return changes_ != seen; });
  return changes_;
}

bool Hub::wait_until_no_clients(std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(m_);
  return cv_.wait_for(lock, wait, [&] { return clients_ == 0; });
}

bool Hub::wait_until_read(std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(m_);
  return cv_.wait_for(lock, wait, [&] { return finished_ > 0 && clients_ == 0; });
}

int Hub::clients() const {
  std::lock_guard<std::mutex> lock(m_);
  return clients_;
}

long long Hub::dropped() const {
  std::lock_guard<std::mutex> lock(m_);
  return dropped_;
}

long long Hub::published() const {
  std::lock_guard<std::mutex> lock(m_);
  return first_ + static_cast<long long>(log_.size());
}

}  // namespace vines::host::monitor
