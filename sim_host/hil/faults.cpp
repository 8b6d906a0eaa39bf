#include "sim_host/hil/faults.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <random>
#include <stdexcept>

namespace vines::host {

const char* fault_kind_name(FaultKind k) {
  static const char* const kNames[kFaultKinds] = {"drop",      "corrupt",  "duplicate", "reorder", "late",
                                                  "nonfinite", "saturate", "stall",     "restart"};
  return kNames[static_cast<int>(k)];
}

FaultSpec parse_fault_spec(const std::string& option, const std::string& value) {
  FaultSpec s;
  const auto bad = [&](const std::string& why) {
    return std::runtime_error(option + " " + value + ": " + why +
                              " (a rate from 0 to 1, or @K1,K2,... sample indices)");
  };
  if (!value.empty() && value[0] == '@') {
    std::size_t i = 1;
    while (i <= value.size()) {
      const std::size_t j = std::min(value.find(',', i), value.size());
      const std::string item = value.substr(i, j - i);
      char* end = nullptr;
      errno = 0;
      const long long k = std::strtoll(item.c_str(), &end, 10);
      if (item.empty() || *end != '\0' || errno || k < 1) throw bad("'" + item + "' is not a sample index >= 1");
      s.at.push_back(k);
      i = j + 1;
    }
    return s;
  }
  char* end = nullptr;
  s.rate = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !(s.rate >= 0 && s.rate <= 1)) throw bad("not a rate");
  return s;
}

std::vector<FaultEvent> plan_faults(const HilOptions& opt, long long samples) {
  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> u(0, 1);
  // Per sample: 0 free, kGap the recovery sample after a fault's window, kHit
  // inside a fault's window.
  constexpr char kGap = 1, kHit = 2;
  std::vector<char> busy(static_cast<std::size_t>(samples) + 1, 0);
  std::vector<FaultEvent> out;
  // Windows: how many samples a fault occupies (nothing else may fall there).
  auto span_of = [&](FaultKind k) {
    switch (k) {
      case FaultKind::kStall: return opt.stall_periods;
      case FaultKind::kLate: return opt.late_periods;
      case FaultKind::kReorder: return 2;
      default: return 1;
    }
  };
  for (long long k = 1; k < samples; ++k) {
    for (int f = 0; f < kFaultKinds; ++f) {
      const auto kind = static_cast<FaultKind>(f);
      if (kind == FaultKind::kSaturate) continue;  // a sensor range, applied to every sample
      const FaultSpec& s = opt.faults[f];
      const bool listed = std::find(s.at.begin(), s.at.end(), k) != s.at.end();
      const bool drawn = s.rate > 0 && u(rng) < s.rate;
      if (!listed && !drawn) continue;
      // A fault the user made certain (listed, or a rate of 1) may take the
      // recovery sample after another fault and may end with the record; a
      // drawn one leaves a free sample after its window, before the end.
      const bool certain = listed || s.rate >= 1;
      const int span = span_of(kind);
      if (certain ? k + span > samples : k + span + 1 >= samples) continue;
      bool free = true;
      for (long long j = k; j <= std::min(k + span, samples - 1) && free; ++j)
        free = busy[static_cast<std::size_t>(j)] == 0 || (certain && busy[static_cast<std::size_t>(j)] == kGap);
      if (!free) continue;
      for (long long j = k; j < k + span; ++j) busy[static_cast<std::size_t>(j)] = kHit;
      busy[static_cast<std::size_t>(k + span)] = std::max(busy[static_cast<std::size_t>(k + span)], kGap);
      FaultEvent ev;
      ev.kind = kind;
      ev.k = k;
      ev.span = span;
      out.push_back(ev);
      break;
    }
  }
  return out;
}

}  // namespace vines::host
