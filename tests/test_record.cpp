// Host HAL backend: record parsing (real files and hand-made good and bad
// files). Resampling and the sample source: test_resample.cpp.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "host/record.hpp"
#include "record_support.hpp"

namespace fs = std::filesystem;
using namespace vines::hal;
using namespace vines::record_test;

namespace {

constexpr double kG = 9.80665;

// ---- helpers ----

// Index of the sample with the largest |a| (the first one on ties).
std::size_t peak_index(const Record& r) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < r.accel_mps2.size(); ++i) {
    if (std::abs(r.accel_mps2[i]) > std::abs(r.accel_mps2[best])) best = i;
  }
  return best;
}


// ---- real records: N, dt, t0 and the signed PGA and its sample from SOURCES.md ----

struct RealCase {
  const char* file;
  Units units;
  int column;
  std::size_t n;
  double dt;
  double t0;
  double pga;  // signed, in the file's units (g, or m/s^2 for Sylmar)
  std::size_t pga_index;
};

const RealCase kRealCases[] = {
    {"elcentro_1940_ns_peknold_dt002.at2", Units::kG, 1, 1559, 0.02, 0.0, -0.31882, 101},
    {"elcentro_1940_ns_peer_legacy_I-ELC180_dt001.at2", Units::kG, 1, 4000, 0.01, 0.0, -0.31288,
     215},
    {"elcentro_1940_ns_peer_nga_west2_rsn6_I-ELC180.at2", Units::kG, 1, 5372, 0.01, 0.0, -0.28080,
     218},
    {"elcentro_1940_ns_2688pts_dt002_time_g.dat", Units::kG, 1, 2688, 0.02, 0.0, +0.34874, 106},
    {"taft_1952_kern_county_TAF021_nga_west2_rsn15.at2", Units::kG, 1, 5435, 0.01, 0.0, -0.15889,
     914},
    {"kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2", Units::kG, 1, 7500, 0.02, 0.0, -0.83423, 426},
    {"northridge_1994_sylmar_county_hospital_ns_time_ms2.dat", Units::kMps2, 1, 3000, 0.02, 0.0,
     +8.2676, 210},
    {"northridge_1994_rinaldi_228_nga_rsn1063.at2", Units::kG, 1, 1991, 0.01, 0.0, -0.87406, 256},
    {"lomaprieta_1989_corralitos_CLS000_nga_west2_rsn753.at2", Units::kG, 1, 7997, 0.005, 0.0,
     +0.64473, 525},
    {"mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt", Units::kG, 1, 8171, 0.02, 0.02, +0.09953,
     2708},
    {"mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt", Units::kG, 2, 8171, 0.02, 0.02, +0.17117,
     2904},
    {"mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt", Units::kG, 3, 8171, 0.02, 0.02, -0.03734,
     3083},
};

class RealRecords : public ::testing::TestWithParam<RealCase> {};

TEST_P(RealRecords, MatchesSources) {
  const RealCase& c = GetParam();
  const std::string dir = motions_dir();
  if (dir.empty() || !fs::is_directory(dir)) GTEST_SKIP() << "no ground-motion folder: " << dir;

  RecordSpec spec = spec_for(dir + "/" + c.file);
  spec.units = c.units;
  spec.column = c.column;
  const Record r = load_record(spec);

  ASSERT_EQ(r.accel_mps2.size(), c.n);
  EXPECT_NEAR(r.dt_s, c.dt, 1e-12);
  EXPECT_NEAR(r.t0_s, c.t0, 1e-12);
  const double per_unit = c.units == Units::kG ? kG : 1.0;
  const std::size_t i = peak_index(r);
  EXPECT_EQ(i, c.pga_index);
  EXPECT_NEAR(r.accel_mps2[i] / per_unit, c.pga, 6e-6 * std::abs(c.pga) + 6e-6);
  EXPECT_DOUBLE_EQ(r.pga_mps2(), std::abs(r.accel_mps2[i]));
}

INSTANTIATE_TEST_SUITE_P(Sources, RealRecords, ::testing::ValuesIn(kRealCases));

// Explicit formats read the same as auto detection; scale multiplies after units.
TEST(RealRecordFormats, ExplicitFormatAndScale) {
  const std::string dir = motions_dir();
  if (dir.empty() || !fs::is_directory(dir)) GTEST_SKIP() << "no ground-motion folder: " << dir;

  const Record kobe = load_record(spec_for(dir + "/kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2"));
  RecordSpec s = spec_for(dir + "/kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2", RecordFormat::kAt2);
  s.scale = -0.5;
  const Record half = load_record(s);
  ASSERT_EQ(half.accel_mps2.size(), kobe.accel_mps2.size());
  for (std::size_t i = 0; i < kobe.accel_mps2.size(); ++i) {
    ASSERT_DOUBLE_EQ(half.accel_mps2[i], -0.5 * kobe.accel_mps2[i]);
  }

  RecordSpec t =
      spec_for(dir + "/elcentro_1940_ns_2688pts_dt002_time_g.dat", RecordFormat::kTimeAccel);
  EXPECT_EQ(load_record(t).accel_mps2.size(), 2688u);
}

// ---- hand-made good files: header variants, number formats, line endings ----

TEST_F(RecordFiles, At2HeaderVariantsAndFortranNumbers) {
  // NPTS on line 2, spaces around '=', CRLF, blank lines, trailing blanks, D exponents, '+'.
  const std::string p = write("v.at2",
                              "SOME RECORD\r\n"
                              "NPTS =   6 , DT =   .010 SEC ,   \r\n"
                              "\r\n"
                              "  .1000000E+01  -.5D0  +2.5   \r\n"
                              "  1.0d-03 -0. 3 \r\n");
  const Record r = load_record(spec_for(p));
  ASSERT_EQ(r.accel_mps2.size(), 6u);
  EXPECT_DOUBLE_EQ(r.dt_s, 0.01);
  const double g[] = {1.0, -0.5, 2.5, 1e-3, 0.0, 3.0};
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(r.accel_mps2[i], g[i] * kG) << i;
}

TEST_F(RecordFiles, At2UnitsFromHeader) {
  const std::string body = "NPTS= 2, DT= .02000 SEC\n 100. 200.\n";
  const Record cm =
      load_record(spec_for(write("cm.at2", "ACCELERATION IN UNITS OF CM/S/S\n" + body)));
  EXPECT_DOUBLE_EQ(cm.accel_mps2[1], 2.0);
  const Record gal = load_record(spec_for(write("gal.at2", "The units are (gal)\n" + body)));
  EXPECT_DOUBLE_EQ(gal.accel_mps2[0], 1.0);
  const Record g = load_record(spec_for(write("g.at2", "Peknold\nThe units are (g)\n" + body)));
  EXPECT_DOUBLE_EQ(g.accel_mps2[0], 100.0 * kG);
  // No units in the header: the spec's units apply.
  RecordSpec s = spec_for(write("none.at2", "TITLE\n" + body));
  s.units = Units::kMps2;
  EXPECT_DOUBLE_EQ(load_record(s).accel_mps2[0], 100.0);
}

TEST_F(RecordFiles, ColumnsWithCommentsCrlfAndOffset) {
  const std::string p = write("c.txt",
                              "# time  a1  a2\r\n"
                              "\r\n"
                              "1.00\t10\t-20   \r\n"
                              "1.50 30 -40 # comment\r\n"
                              "# interlude\r\n"
                              "2.00 50 -60\r\n");
  RecordSpec s = spec_for(p);
  s.units = Units::kCmps2;
  s.column = 2;
  s.scale = 2.0;
  const Record r = load_record(s);
  ASSERT_EQ(r.accel_mps2.size(), 3u);
  EXPECT_DOUBLE_EQ(r.t0_s, 1.0);
  EXPECT_DOUBLE_EQ(r.dt_s, 0.5);
  EXPECT_DOUBLE_EQ(r.accel_mps2[0], -0.4);
  EXPECT_DOUBLE_EQ(r.accel_mps2[2], -1.2);
  EXPECT_DOUBLE_EQ(r.pga_mps2(), 1.2);
}

TEST_F(RecordFiles, TimeJitterWithinToleranceIsAccepted) {
  // Times printed to 5 decimals, as in the Mexico record.
  const Record r =
      load_record(spec_for(write("j.txt", "0.02 1\n0.03999 2\n0.06000 3\n0.08001 4\n0.1 5\n")));
  EXPECT_DOUBLE_EQ(r.dt_s, 0.02);
  EXPECT_DOUBLE_EQ(r.t0_s, 0.02);
}

TEST_F(RecordFiles, AccelOnlyNeedsDt) {
  const std::string multi = write("m.txt", "1 2 3\n4 5\n\n6\n");
  RecordSpec s = spec_for(multi, RecordFormat::kAccel);
  s.dt_s = 0.005;
  s.units = Units::kMps2;
  const Record r = load_record(s);
  ASSERT_EQ(r.accel_mps2.size(), 6u);
  EXPECT_DOUBLE_EQ(r.accel_mps2[5], 6.0);
  EXPECT_DOUBLE_EQ(r.dt_s, 0.005);
  EXPECT_DOUBLE_EQ(r.t0_s, 0.0);

  // Auto: one column is accel-only.
  RecordSpec one = spec_for(write("one.txt", "0.1\n0.2\n"));
  one.dt_s = 0.01;
  EXPECT_DOUBLE_EQ(load_record(one).accel_mps2[1], 0.2 * kG);
}

// ---- bad files: each error names the file and, where it applies, the line ----

TEST_F(RecordFiles, MissingOrUnreadable) {
  const std::string missing = (dir_ / "nope.at2").string();
  EXPECT_NE(error_of(spec_for(missing)).find(missing + ": file not found"), std::string::npos);
  EXPECT_NE(error_of(spec_for(dir_.string())).find("directory"), std::string::npos);
}

TEST_F(RecordFiles, EmptyAndNoSamples) {
  const std::string empty = write("empty.txt", "");
  EXPECT_EQ(error_of(spec_for(empty)), empty + ": empty file");
  const std::string blank = write("blank.txt", "\n  \r\n\t\n");
  EXPECT_EQ(error_of(spec_for(blank)), blank + ": empty file");
  const std::string comments = write("comments.txt", "# nothing\n# here\n");
  EXPECT_EQ(error_of(spec_for(comments)), comments + ": no samples");
  const std::string header_only = write("h.at2", "NPTS= 3, DT= .01 SEC\n");
  EXPECT_EQ(error_of(spec_for(header_only)),
            header_only + ":1: NPTS=3 in the header but 0 values read");
}

TEST_F(RecordFiles, NonNumericToken) {
  const std::string p = write("bad.at2", "T\nT\nT\nNPTS= 4, DT= .01\n 1 2\n 3 x4y\n");
  const std::string e = error_of(spec_for(p));
  EXPECT_NE(e.find(p + ":6:"), std::string::npos) << e;
  EXPECT_NE(e.find("'x4y'"), std::string::npos) << e;
  // Glued or doubled signs are not numbers either.
  const std::string q = write("signs.txt", "0 1\n0.01 +-1\n");
  EXPECT_NE(error_of(spec_for(q)).find(q + ":2: non-numeric token '+-1'"), std::string::npos);
}

TEST_F(RecordFiles, NonFiniteValues) {
  for (const char* tok : {"nan", "NaN", "inf", "-Infinity", "1e999"}) {
    const std::string p = write("nf.txt", std::string("0 1\n0.01 2\n\n0.02 ") + tok + "\n");
    const std::string e = error_of(spec_for(p));
    EXPECT_NE(e.find(p + ":4: non-finite value '" + tok + "'"), std::string::npos) << e;
  }
}

TEST_F(RecordFiles, NptsMismatch) {
  const std::string p = write("n.at2", "A\nB\nUNITS OF G\nNPTS=  5, DT= .02000 SEC\n1 2 3 4\n");
  const std::string e = error_of(spec_for(p));
  EXPECT_EQ(e, p + ":4: NPTS=5 in the header but 4 values read");
  const std::string more = write("m.at2", "NPTS=  2, DT= .02\n1 2 3\n");
  EXPECT_NE(error_of(spec_for(more)).find("NPTS=2 in the header but 3 values read"),
            std::string::npos);
}

TEST_F(RecordFiles, BadHeaderDt) {
  const std::string zero = write("z.at2", "X\nNPTS= 2, DT= 0.0 SEC\n1 2\n");
  EXPECT_NE(error_of(spec_for(zero)).find(zero + ":2: DT must be positive"), std::string::npos);
  const std::string neg = write("n.at2", "NPTS= 2, DT= -.01 SEC\n1 2\n");
  EXPECT_NE(error_of(spec_for(neg)).find(neg + ":1: DT must be positive"), std::string::npos);
  const std::string junk = write("j.at2", "NPTS= 2, DT= ..1 SEC\n1 2\n");
  EXPECT_NE(error_of(spec_for(junk)).find(junk + ":1: non-numeric token '..1'"), std::string::npos);
  const std::string none = write("none.at2", "1 2\n3 4\n");
  EXPECT_NE(error_of(spec_for(none, RecordFormat::kAt2)).find("no 'NPTS= .., DT= ..' header"),
            std::string::npos);
  const std::string vel =
      write("v.vt2", "PEER\nX\nVELOCITY TIME SERIES IN UNITS OF CM/S\nNPTS= 1, DT= .01\n1\n");
  EXPECT_EQ(error_of(spec_for(vel)), vel + ":3: not an acceleration record");
}

// A header's DT that is not a number is named as such (not taken for no
// header); units vines does not know are refused, not read as g; a record of
// one point is refused in every format.
TEST_F(RecordFiles, HeaderDtUnitsAndOnePointAreChecked) {
  const std::string nan = write("nan.at2", "PEER\nNPTS= 2, DT=nan\n1 2\n");
  EXPECT_EQ(error_of(spec_for(nan)), nan + ":2: non-finite value 'nan'");
  const std::string inch = write("in.at2", "ACCELERATION IN UNITS OF IN/S/S\nNPTS= 2, DT= .01 SEC\n1 2\n");
  EXPECT_EQ(error_of(spec_for(inch)), inch + ":1: unknown units 'IN/S/S' (vines reads g, gal, cm/s2, m/s2)");
  const std::string one = write("one.at2", "UNITS OF G\nNPTS= 1, DT= .01 SEC\n1\n");
  EXPECT_EQ(error_of(spec_for(one)), one + ": a record needs at least 2 points, it has 1");
  const std::string col = write("one.txt", "0.0 1.0\n");
  EXPECT_NE(error_of(spec_for(col)).find("at least 2"), std::string::npos);
}

TEST_F(RecordFiles, BadTimeColumn) {
  const std::string same = write("s.txt", "0 1\n0.02 1\n0.02 1\n0.06 1\n");
  EXPECT_NE(error_of(spec_for(same)).find(same + ":3: time does not increase"), std::string::npos);
  const std::string back = write("b.txt", "0 1\n# c\n0.02 1\n0.01 1\n0.06 1\n");
  EXPECT_NE(error_of(spec_for(back)).find(back + ":4: time does not increase"), std::string::npos);
  const std::string uneven = write("u.txt", "0 1\n0.02 1\n0.05 1\n0.06 1\n");
  EXPECT_NE(error_of(spec_for(uneven)).find(uneven + ":3: non-uniform time step"),
            std::string::npos);
  // Steps within tolerance that drift off the grid are caught too.
  const std::string drift =
      write("d.txt", "0 1\n0.9992 1\n1.9984 1\n2.9976 1\n3.9984 1\n4.9992 1\n6 1\n");
  EXPECT_NE(error_of(spec_for(drift)).find(drift + ":3: non-uniform"), std::string::npos);
  const std::string single = write("one.txt", "0.5 1\n");
  EXPECT_NE(error_of(spec_for(single)).find(single + ":1: a time column needs at least 2"),
            std::string::npos);
}

TEST_F(RecordFiles, MissingDt) {
  const std::string p = write("a.txt", "1\n2\n");
  EXPECT_NE(error_of(spec_for(p)).find(p + ": accel-only record needs dt > 0"), std::string::npos);
  RecordSpec s = spec_for(p, RecordFormat::kAccel);
  s.dt_s = -0.01;
  EXPECT_NE(error_of(s).find("needs dt > 0"), std::string::npos);
}

TEST_F(RecordFiles, ColumnOutOfRangeAndRagged) {
  const std::string p = write("c.txt", "\n0 1 2 3\n0.1 1 2 3\n");
  RecordSpec s = spec_for(p);
  s.column = 4;
  EXPECT_EQ(error_of(s), p + ":2: column 4 out of range: the file has 3 acceleration column(s)");
  s.column = 0;
  EXPECT_NE(error_of(s).find("column 0 out of range"), std::string::npos);
  const std::string one = write("one.txt", "1\n2\n");
  EXPECT_NE(
      error_of(spec_for(one, RecordFormat::kTimeAccel)).find(one + ":1: time/accel record needs"),
      std::string::npos);

  const std::string ragged = write("r.txt", "0 1 2\n0.1 1 2\n0.2 1\n");
  EXPECT_EQ(error_of(spec_for(ragged)), ragged + ":3: expected 3 columns, found 2");
}

TEST_F(RecordFiles, BinaryGarbageIsAnErrorNotACrash) {
  std::string bytes(4096, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 37) & 0xff);
  const std::string p = write("garbage.bin", bytes);
  EXPECT_NE(error_of(spec_for(p)).find(p + ":"), std::string::npos);
}

// parse_record (the fuzzer's entry): the file's text in memory gives the same
// record, or the same refusal naming spec.path, as load_record on the file.
TEST_F(RecordFiles, TextInMemoryReadsAsTheFile) {
  const std::string text = "X\nNPTS= 3, DT= .02 SEC\n 1. -2.5D-1\r\n 3.\n";
  const RecordSpec file = spec_for(write("m.at2", text));
  const Record a = load_record(file);
  const Record b = parse_record(text, file);
  EXPECT_EQ(a.accel_mps2, b.accel_mps2);
  EXPECT_EQ(a.dt_s, b.dt_s);
  EXPECT_EQ(b.path, file.path);
  for (const std::string bad : {"", "NPTS= 2, DT= .01\n1 x\n"}) {
    const std::string p = write("bad.at2", bad);
    try {
      parse_record(bad, spec_for(p));
      ADD_FAILURE() << "no RecordError for '" << bad << "'";
    } catch (const RecordError& e) {
      EXPECT_EQ(std::string(e.what()), error_of(spec_for(p)));
    }
  }
}

// A few bytes must not ask for days of samples (found by record_fuzz: NPTS=2
// with DT=33333 took seconds to resample, a run would simulate 18 hours).
TEST_F(RecordFiles, RecordEndingAfterAnHourIsRefused) {
  const std::string late = write("late.txt", "4e5 0\n400000.01 1\n");
  EXPECT_EQ(error_of(spec_for(late)),
            late + ": the record ends at t = 400000.02 s, later than the 3600 s a record may last"
                   " (check DT or the time column)");
  const std::string hour = write("hour.txt", "3500 1\n3500.5 2\n");  // ends at 3501 s
  EXPECT_EQ(load_record(spec_for(hour)).accel_mps2.size(), 2u);
}

}  // namespace
