// `vines sweep`'s plan: the runs a checked spec (sweep_spec.cpp) makes, in
// order, one at a time or all, and the memory the plan takes.
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "sim_host/studies/sweep.hpp"

namespace vines::host {

namespace {

// a * b, or UINT64_MAX when it overflows (or either is).
std::uint64_t times(std::uint64_t a, std::uint64_t b) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  return a != 0 && b > kMax / a ? kMax : a * b;
}

// The runs of one study: its cases times the product of its axis lengths.
std::uint64_t grid_size(const StudySpec& st) {
  std::uint64_t n = 1;
  for (const auto& ax : st.grid_axes) n = times(n, ax.size());
  return n;
}

std::uint64_t study_size(const StudySpec& st) {
  return times(std::max<std::uint64_t>(1, st.cases.size()), grid_size(st));
}

}  // namespace

double plan_memory_bytes(const SweepSpec& spec, std::uint64_t n) {
  std::size_t values = 0;
  for (const StudySpec& st : spec.studies)
    values = std::max(values, (st.cases.empty() ? 0 : st.cases.front().size()) + st.grid_axes.size());
  const double per_run = sizeof(RunPlan) + sizeof(RunResult) + values * (sizeof(KeyValue) + 32.0);
  return static_cast<double>(n) * per_run;
}

double machine_memory_bytes() {
  return static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
}

std::uint64_t plan_size(const SweepSpec& spec) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t n = 0;
  for (const StudySpec& st : spec.studies) {
    const std::uint64_t m = study_size(st);
    n = m > kMax - n ? kMax : n + m;
  }
  return n;
}

// Studies in order; in a study, cases outer, then the grid axes as an
// odometer, last axis fastest.
RunPlan plan_run(const SweepSpec& spec, std::uint64_t index) {
  int s = 0;
  while (index >= study_size(spec.studies[s])) index -= study_size(spec.studies[s++]);
  const StudySpec& st = spec.studies[s];
  const std::uint64_t per_case = grid_size(st);
  RunPlan r{s, st.cases.empty() ? std::vector<KeyValue>{} : st.cases[index / per_case]};
  std::uint64_t rest = index % per_case;
  std::vector<KeyValue> grid(st.grid_axes.size());
  for (std::size_t a = st.grid_axes.size(); a-- > 0;) {
    grid[a] = st.grid_axes[a][rest % st.grid_axes[a].size()];
    rest /= st.grid_axes[a].size();
  }
  r.values.insert(r.values.end(), grid.begin(), grid.end());
  return r;
}

std::vector<RunPlan> plan_runs(const SweepSpec& spec) {
  const std::uint64_t n = plan_size(spec);
  std::vector<RunPlan> out;
  out.reserve(n);
  for (std::uint64_t i = 0; i < n; ++i) out.push_back(plan_run(spec, i));
  return out;
}

}  // namespace vines::host
