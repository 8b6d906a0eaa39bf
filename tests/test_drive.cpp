// drive(): the one loop of every host run, fed by the HAL's ground source.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <vector>

#include "host/record.hpp"
#include "sim_host/run/drive.hpp"

namespace {

using vines::hal::RecordSource;
using vines::host::drive;
using vines::host::kDriveBlock;

// A target that keeps what it was fed, in order, and how.
struct Recorder {
  std::vector<double> seen;
  int inits = 0;
  std::size_t largest_block = 0;
  void init(double a) {
    ++inits;
    seen.push_back(a);
  }
  void run(const double* a, std::size_t n) {
    largest_block = std::max(largest_block, n);
    seen.insert(seen.end(), a, a + n);
  }
};

std::vector<double> ramp(std::size_t n) {
  std::vector<double> v(n);
  for (std::size_t k = 0; k < n; ++k) v[k] = 0.25 * static_cast<double>(k);
  return v;
}

TEST(Drive, EverySampleOnceInOrderFirstToInit) {
  for (const std::size_t n : {std::size_t{1}, std::size_t{2}, kDriveBlock, kDriveBlock + 1, std::size_t{5000}}) {
    const std::vector<double> a = ramp(n);
    RecordSource src(a, 1000.0);
    Recorder r;
    EXPECT_EQ(drive(r, src), n);
    EXPECT_EQ(r.inits, 1);
    EXPECT_EQ(r.seen, a) << n;
    EXPECT_LE(r.largest_block, kDriveBlock);
  }
  const std::vector<double> none;
  RecordSource empty(none, 1000.0);
  Recorder r;
  EXPECT_EQ(drive(r, empty), 0u);
  EXPECT_EQ(r.inits, 0);
}

TEST(Drive, ObservesAtEveryMultipleWithTheStateThen) {
  for (const std::size_t every : {std::size_t{1}, std::size_t{7}, std::size_t{10}, kDriveBlock, std::size_t{1300}}) {
    const std::vector<double> a = ramp(4001);
    RecordSource src(a, 1000.0);
    Recorder r;
    std::vector<std::size_t> at;
    drive(r, src, every, [&](std::size_t k) {
      EXPECT_EQ(r.seen.size(), k + 1) << "observed after sample k, with samples 0..k fed";
      at.push_back(k);
    });
    std::vector<std::size_t> want;
    for (std::size_t k = 0; k < a.size(); k += every) want.push_back(k);
    EXPECT_EQ(at, want) << "every " << every;
    EXPECT_EQ(r.seen, a);
  }
}

TEST(Drive, AStopEndsTheFeedBetweenBlocks) {
  const std::vector<double> a = ramp(10 * kDriveBlock);
  RecordSource src(a, 1000.0);
  Recorder r;
  std::atomic<bool> stop{false};
  const std::size_t fed = drive(r, src, kDriveBlock, [&](std::size_t k) {
    if (k == 2 * kDriveBlock) stop = true;
  }, &stop);
  EXPECT_EQ(fed, 2 * kDriveBlock + 1);
  EXPECT_EQ(r.seen.size(), fed);
}

}  // namespace
