#include "sim_host/monitor/decimator.hpp"

#include <stdexcept>

#include <nlohmann/json.hpp>

namespace vines::host::monitor {

std::string sse_event(const std::string& name, const std::string& data) {
  return "event: " + name + "\ndata: " + data + "\n\n";
}

Decimator::Decimator(int every, int per_frame, std::size_t width)
    : every_(every), per_frame_(per_frame), v_(width) {
  if (every < 1 || per_frame < 1) throw std::invalid_argument("Decimator: every and per_frame must be >= 1");
}

bool Decimator::add(long long k, const std::vector<double>& v, std::string* event) {
  if (v.size() != v_.size()) throw std::invalid_argument("Decimator: a row of " + std::to_string(v.size()) +
                                                         " values for " + std::to_string(v_.size()) + " series");
  last_ = k;
  k_.push_back(k);
  for (std::size_t j = 0; j < v.size(); ++j) v_[j].push_back(v[j]);
  return static_cast<int>(k_.size()) >= per_frame_ && flush(event);
}

bool Decimator::flush(std::string* event) {
  if (k_.empty()) return false;
  // nlohmann writes a double as the shortest text that reads back to it, and
  // NaN or inf as null.
  const nlohmann::json j = {{"k", k_}, {"v", v_}};
  *event = sse_event("frame", j.dump());
  k_.clear();
  for (auto& s : v_) s.clear();
  return true;
}

}  // namespace vines::host::monitor
