// Host HAL backend: what a record file may be (a regular file of bounded size,
// points and dt), the format detected from each kind of file, and a
// `--record` file read in its own format or the one forced.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "host/record.hpp"
#include "record_support.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"

using namespace vines::hal;
using namespace vines::record_test;

namespace {

// ---- files that are not records: refused before any read ----

TEST_F(RecordFiles, DevicesFifosAndFoldersAreRefused) {
  EXPECT_EQ(error_of(spec_for("/dev/zero")),
            "/dev/zero: not a regular file (a device, FIFO or socket): only files on disk are read");
  EXPECT_EQ(error_of(spec_for(dir_.string())), dir_.string() + ": is a directory, not a file");
  const std::string fifo = (dir_ / "fifo.at2").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(error_of(spec_for(fifo)).find(fifo + ": not a regular file"), std::string::npos);
  EXPECT_EQ(error_of(spec_for((dir_ / "nope.at2").string())), (dir_ / "nope.at2").string() + ": file not found");
}

// A file over the size bound is refused from its size alone (a sparse file:
// nothing is read).
TEST_F(RecordFiles, OversizeFileIsRefused) {
  const std::string big = write("big.txt", "");
  std::filesystem::resize_file(big, kMaxRecordBytes + 1);
  EXPECT_EQ(error_of(spec_for(big)),
            big + ": file of 33554433 bytes: larger than the 33554432 bytes an input may have");
}

// Points: too many lines, an NPTS header beyond the bound, too many values.
TEST_F(RecordFiles, TooManyPointsAreRefused) {
  const std::string lines = write("lines.txt", std::string(kMaxRecordPoints + 1, '\n'));
  EXPECT_NE(error_of(spec_for(lines)).find("2000001 lines: more than the 2000000"), std::string::npos);
  const std::string npts = write("npts.at2", "PEER\nx\nx\nNPTS= 9000000, DT= .01 SEC\n0.1\n");
  EXPECT_EQ(error_of(spec_for(npts)), npts + ":4: 9000000 points (NPTS): more than the 2000000 a record may have");
  std::string row;
  for (int i = 0; i < 8; ++i) row += "0 ";
  std::string body;
  for (std::size_t i = 0; i < kMaxRecordPoints / 8 + 1; ++i) body += row + "\n";
  RecordSpec values = spec_for(write("values.txt", body), RecordFormat::kAccel);
  values.dt_s = 0.01;
  EXPECT_NE(error_of(values).find("2000008 points: more than the 2000000"), std::string::npos);
}

// dt outside [1e-6, 1] s, from each source of dt.
TEST_F(RecordFiles, AbsurdDtIsRefused) {
  const std::string slow = write("slow.txt", "0 0.1\n2 0.2\n4 0.3\n");
  EXPECT_EQ(error_of(spec_for(slow)), slow + ": dt 2 s is outside [1e-06, 1] s");
  const std::string fast = write("fast.at2", "PEER\nNPTS= 2, DT= 1e-9 SEC\n0.1 0.2\n");
  EXPECT_EQ(error_of(spec_for(fast)), fast + ": dt 1e-09 s is outside [1e-06, 1] s");
  RecordSpec values = spec_for(write("values.txt", "0.1\n0.2\n"), RecordFormat::kAccel);
  values.dt_s = 1e3;
  EXPECT_EQ(error_of(values), values.path + ": dt 1000 s is outside [1e-06, 1] s");
}

// ---- format detection: each kind of shipped record ----

TEST(RecordFormatDetection, EachShippedKind) {
  const std::string gm = motions_dir() + "/";
  EXPECT_EQ(detect_record_format(gm + "elcentro_1940_ns_peknold_dt002.at2"), RecordFormat::kAt2);
  EXPECT_EQ(detect_record_format(gm + "elcentro_1940_ns_peer_legacy_I-ELC180_dt001.at2"), RecordFormat::kAt2);
  EXPECT_EQ(detect_record_format(gm + "kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2"), RecordFormat::kAt2);
  EXPECT_EQ(detect_record_format(gm + "elcentro_1940_ns_2688pts_dt002_time_g.dat"), RecordFormat::kTimeAccel);
  EXPECT_EQ(detect_record_format(gm + "mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt"), RecordFormat::kTimeAccel);
  EXPECT_EQ(detect_record_format(gm + "northridge_1994_sylmar_county_hospital_ns_time_ms2.dat"),
            RecordFormat::kTimeAccel);
}

TEST_F(RecordFiles, DetectsValuesOnly) {
  EXPECT_EQ(detect_record_format(write("v.txt", "# a comment\n0.1\n0.2\n")), RecordFormat::kAccel);
  EXPECT_THROW(detect_record_format("/dev/zero"), RecordError);
}

// ---- --record PATH: the file's own format, or the one forced ----

using vines::host::load_excitation;
using vines::host::RecordReading;

vines::host::Scene tmd_scene() {
  return vines::host::load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_tmd.toml");
}

TEST_F(RecordFiles, OverrideOfValuesNeedsItsDt) {
  const std::string values = write("values.txt", "0.1\n-0.2\n0.05\n");
  try {
    load_excitation(tmd_scene(), values);
    FAIL() << "a values-only --record without --record-dt was read";
  } catch (const RecordError& e) {
    EXPECT_EQ(std::string(e.what()), "--record " + values +
                                         ": one column of values and no time: give its sample step with "
                                         "--record-dt SECONDS (or --record-format for another format)");
  }
  RecordReading how;
  how.dt_s = 0.01;
  EXPECT_EQ(load_excitation(tmd_scene(), values, how).record.dt_s, 0.01);
}

// Forcing a format reads the file that way: time/accel columns forced to
// values-only read every number; an AT2 forced to columns is refused.
TEST_F(RecordFiles, OverrideFormatIsForced) {
  const std::string cols = write("cols.txt", "0 0.1\n0.01 0.2\n0.02 0.3\n");
  EXPECT_EQ(load_excitation(tmd_scene(), cols).record.accel_mps2.size(), 3u);
  RecordReading how;
  how.format = RecordFormat::kAccel;
  how.dt_s = 0.005;
  const std::string pairs = write("pairs.txt", "0.1 0.2\n0.3 0.1\n-0.2 0.4\n");  // accelerations, two a line
  EXPECT_EQ(load_excitation(tmd_scene(), pairs, how).record.accel_mps2.size(), 6u);
  // A time column is not read as accelerations.
  try {
    load_excitation(tmd_scene(), cols, how);
    ADD_FAILURE() << "a time column read as accelerations";
  } catch (const RecordError& e) {
    EXPECT_NE(std::string(e.what()).find("a time column (use format \"time-accel\""), std::string::npos) << e.what();
  }
  RecordReading at2;
  at2.format = RecordFormat::kTimeAccel;
  const std::string kobe = motions_dir() + "/kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2";
  EXPECT_THROW(load_excitation(tmd_scene(), kobe, at2), RecordError);
}

// The units and the column are the override's, not the scene's: a columns
// file in m/s^2 read as such, the second acceleration column picked.
TEST_F(RecordFiles, OverrideUnitsAndColumn) {
  const std::string cols = write("cols.txt", "0 1.0 2.0\n0.01 1.0 2.0\n");
  vines::host::Scene scene = tmd_scene();
  scene.record.units = Units::kCmps2;  // the scene's own file's units: not used
  EXPECT_DOUBLE_EQ(load_excitation(scene, cols).record.accel_mps2[0], 9.80665);
  RecordReading how;
  how.units = Units::kMps2;
  how.column = 2;
  EXPECT_DOUBLE_EQ(load_excitation(scene, cols, how).record.accel_mps2[0], 2.0);
}

}  // namespace
