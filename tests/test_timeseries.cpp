// `vines run`'s timeseries, in both formats, read back bit for bit: the CSV
// through strtod, the .npy through its header (as numpy.lib.format defines
// it) and raw bytes, each against the series the run kept in memory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"

namespace vines::host {
namespace {

namespace fs = std::filesystem;

// The El Centro VI NES scene, first 3 s, timeseries in `format`.
Scene short_scene(TimeseriesFormat format) {
  Scene s = load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines.toml");
  s.duration_s = 3.0;
  s.output.format = format;
  return s;
}

// The values the file must hold, row by row, in the columns' order.
std::vector<std::vector<double>> expected_rows(const RunReport& r) {
  std::vector<std::vector<double>> rows;
  const int n = r.info.stories;
  for (std::size_t k = 0; k < r.series.size(); ++k) {
    const Snapshot& s = r.series[k];
    std::vector<double> v{s.t, s.ag};
    for (const FloorArray* a : {&s.x, &s.v, &s.acc, &s.drift}) v.insert(v.end(), a->begin(), a->begin() + n);
    v.push_back(s.elastic_energy);
    v.insert(v.end(), {s.particle_x, s.particle_v, s.wall_left, s.wall_right, s.contact_force,
                       static_cast<double>(s.mode)});
    v.insert(v.end(), {r.bare_series[k].x[n - 1], r.bare_series[k].elastic_energy});
    rows.push_back(v);
  }
  return rows;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

class TimeseriesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vines_timeseries_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  RunReport run(TimeseriesFormat f) {
    RunOptions o;
    o.out_dir = dir_.string();
    o.quiet = true;
    o.keep_series = true;
    return run_scene(short_scene(f), o);
  }
  fs::path dir_;
};

TEST_F(TimeseriesTest, CsvReadsBackBitForBit) {
  const RunReport r = run(TimeseriesFormat::kCsv);
  const std::vector<std::vector<double>> want = expected_rows(r);
  ASSERT_EQ(want.size(), 301u);  // 3 s at 100 Hz, both ends
  std::ifstream in(dir_ / "timeseries.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line.rfind("t_s,ag_mps2,x1_m,", 0), 0u) << line;
  EXPECT_NE(line.find(",contact_mode,bare_x_top_m,bare_Ee_Js"), std::string::npos) << line;
  std::size_t row = 0, mismatches = 0;
  for (; std::getline(in, line); ++row) {
    ASSERT_LT(row, want.size());
    std::istringstream cells(line);
    std::string cell;
    std::size_t col = 0;
    for (; std::getline(cells, cell, ','); ++col) {
      ASSERT_LT(col, want[row].size());
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      EXPECT_EQ(*end, '\0') << cell;
      mismatches += !same_bits(v, want[row][col]);
    }
    EXPECT_EQ(col, want[row].size());
  }
  EXPECT_EQ(row, want.size());
  EXPECT_EQ(mismatches, 0u);
  EXPECT_FALSE(fs::exists(dir_ / "timeseries.npy"));
}

TEST_F(TimeseriesTest, NpyReadsBackBitForBitAndReplacesTheCsv) {
  run(TimeseriesFormat::kCsv);
  const RunReport r = run(TimeseriesFormat::kNpy);
  EXPECT_FALSE(fs::exists(dir_ / "timeseries.csv"));  // the earlier run's, removed
  const std::vector<std::vector<double>> want = expected_rows(r);
  std::ifstream in(dir_ / "timeseries.npy", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 10u);
  ASSERT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  const std::size_t header = static_cast<unsigned char>(bytes[8]) | static_cast<std::size_t>(bytes[9]) << 8;
  EXPECT_EQ((10 + header) % 64, 0u);
  const std::string dict = bytes.substr(10, header);
  EXPECT_NE(dict.find("('t_s', '<f8'), ('ag_mps2', '<f8'), ('x1_m', '<f8')"), std::string::npos) << dict;
  EXPECT_NE(dict.find("('contact_mode', '<i4')"), std::string::npos) << dict;
  EXPECT_NE(dict.find("'shape': (301,)"), std::string::npos) << dict;
  // Rows of 8-byte values, the contact mode as 4 bytes.
  const std::size_t cols = want[0].size(), mode_col = cols - 3;
  const std::size_t row_bytes = 8 * (cols - 1) + 4;
  ASSERT_EQ(bytes.size(), 10 + header + want.size() * row_bytes);
  std::size_t mismatches = 0;
  for (std::size_t k = 0; k < want.size(); ++k) {
    const char* p = bytes.data() + 10 + header + k * row_bytes;
    for (std::size_t c = 0; c < cols; ++c) {
      if (c == mode_col) {
        std::int32_t m;
        std::memcpy(&m, p, 4);
        mismatches += m != static_cast<std::int32_t>(want[k][c]);
        p += 4;
      } else {
        double v;
        std::memcpy(&v, p, 8);
        mismatches += !same_bits(v, want[k][c]);
        p += 8;
      }
    }
  }
  EXPECT_EQ(mismatches, 0u);
}

}  // namespace
}  // namespace vines::host
