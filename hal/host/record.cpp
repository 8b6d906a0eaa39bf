// Host HAL backend: record files (PEER AT2, time/accel columns, accel-only),
// read and checked (resample.cpp: to the sensor rate, and the sample source).
#include "host/record.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <regex>
#include <string_view>

#include "host/record_error.hpp"

namespace vines::hal {
namespace {

constexpr double kG = 9.80665;                    // m/s^2 per g
constexpr std::size_t kHeaderSearchLines = 10;    // AT2 NPTS/DT line must be within these
constexpr double kTimeTolerance = 1e-3;           // allowed time-column jitter, relative to dt
constexpr double kMaxRecordEndS = 3600.0;         // a record ends within the hour (real ones: minutes)

using detail::fail;
using detail::fmt;

// Lines, points: at most kMaxRecordPoints of them.
void check_count(const std::string& where, std::size_t n, const std::string& what) {
  if (n > kMaxRecordPoints) {
    fail(where, std::to_string(n) + " " + what + ": more than the " + std::to_string(kMaxRecordPoints) +
                    " a record may have");
  }
}

// ---- reading: the file as lines, trailing whitespace and CR removed ----

struct Line {
  std::size_t number;  // 1-based
  std::string text;
};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// The lines of a record's text (a file's content, or text in memory); `path`
// names it in messages.
std::vector<Line> split_lines(const std::string& content, const std::string& path) {
  check_count(path, static_cast<std::size_t>(std::count(content.begin(), content.end(), '\n')), "lines");
  std::vector<Line> lines;
  std::istringstream in(content);
  std::string text;
  for (std::size_t n = 1; std::getline(in, text); ++n) {
    while (!text.empty() && is_space(text.back())) text.pop_back();
    lines.push_back({n, std::move(text)});
  }
  const bool blank =
      std::all_of(lines.begin(), lines.end(), [](const Line& l) { return l.text.empty(); });
  if (blank) fail(path, "empty file");
  return lines;
}

// The lines of a record file (a regular file of at most kMaxRecordBytes).
std::vector<Line> read_lines(const std::string& path) {
  std::string content;
  try {
    content = read_input_file(path, kMaxRecordBytes);
  } catch (const std::runtime_error& e) {
    throw RecordError(e.what());
  }
  return split_lines(content, path);
}

// Splits a line on whitespace; text from a '#' on is dropped when asked (column files).
std::vector<std::string_view> tokens(std::string_view s, bool strip_comment) {
  if (strip_comment) s = s.substr(0, s.find('#'));
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_space(s[i])) ++i;
    const std::size_t start = i;
    while (i < s.size() && !is_space(s[i])) ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

// ---- numbers: C / Fortran E, F and D formats; NaN, inf, junk refused ----

double parse_number(std::string_view token, const std::string& path, std::size_t line) {
  const std::string quoted = "'" + std::string(token) + "'";
  std::string s(token);
  std::replace(s.begin(), s.end(), 'D', 'E');  // Fortran double exponent: 1.0D-03
  std::replace(s.begin(), s.end(), 'd', 'e');
  std::size_t skip = 0;  // from_chars refuses a leading '+'
  if (s.size() > 1 && s[0] == '+' && s[1] != '+' && s[1] != '-') skip = 1;

  double v = 0.0;
  const char* first = s.data() + skip;
  const char* last = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ptr != last || ec == std::errc::invalid_argument) {
    fail(path, line, "non-numeric token " + quoted);
  }
  // Out of range: underflow is a harmless tiny value, overflow is an error.
  if (ec == std::errc::result_out_of_range) v = std::strtod(first, nullptr);
  if (!std::isfinite(v)) fail(path, line, "non-finite value " + quoted);
  return v;
}

// ---- PEER AT2 header: NPTS and DT on one line, units on any header line ----

struct At2Header {
  std::size_t line_index;  // index into lines of the NPTS/DT line
  std::size_t npts;
  double dt;
  std::optional<Units> units;
};

std::optional<At2Header> find_at2_header(const std::vector<Line>& lines, const std::string& path) {
  static const std::regex npts_re(R"(\bNPTS\s*=\s*(\d+))", std::regex::icase);
  static const std::regex dt_re(R"(\bDT\s*=\s*([^\s,]*))", std::regex::icase);
  static const std::regex units_re(
      R"((?:units\s+(?:are\s+|of\s+|in\s+)*\(?|\()\s*(gal|cm/s(?:ec)?|m/s(?:ec)?|g)(?![a-z]))",
      std::regex::icase);
  // A header that names its units, whatever they are: unknown ones are refused, not read as g.
  static const std::regex named_units_re(R"(units\s+(?:are\s+|of\s+|in\s+)*\(?\s*([^\s),.;]+))",
                                         std::regex::icase);
  static const std::regex not_accel_re(R"(\b(velocity|displacement)\s+time\s+(series|history))",
                                       std::regex::icase);

  const std::size_t n = std::min(lines.size(), kHeaderSearchLines);
  for (std::size_t i = 0; i < n; ++i) {
    std::smatch npts_m, dt_m;
    const std::string& text = lines[i].text;
    if (!std::regex_search(text, npts_m, npts_re) || !std::regex_search(text, dt_m, dt_re)) {
      continue;
    }
    At2Header h{i, 0, 0.0, std::nullopt};
    const std::string npts = npts_m[1].str();
    const auto r = std::from_chars(npts.data(), npts.data() + npts.size(), h.npts);
    if (r.ec != std::errc() || h.npts == 0) fail(path, lines[i].number, "bad NPTS '" + npts + "'");
    check_count(path + ":" + std::to_string(lines[i].number), h.npts, "points (NPTS)");
    // The time step, less a unit glued to it (".0200SEC").
    std::string dt = dt_m[1].str();
    while (dt.size() > 1 && std::isalpha(static_cast<unsigned char>(dt.back())) && dt.back() != 'n' &&
           dt.back() != 'N' && dt.back() != 'f' && dt.back() != 'F')
      dt.pop_back();
    if (dt.empty()) fail(path, lines[i].number, "no value after DT=");
    h.dt = parse_number(dt, path, lines[i].number);
    if (!(h.dt > 0.0)) fail(path, lines[i].number, "DT must be positive, got " + dt_m[1].str());

    // Header lines up to the NPTS line: refuse velocity/displacement files
    // (.VT2/.DT2); units from the first line that names them.
    for (std::size_t j = 0; j <= i; ++j) {
      std::smatch m;
      if (std::regex_search(lines[j].text, not_accel_re)) {
        fail(path, lines[j].number, "not an acceleration record");
      }
      if (h.units) continue;
      if (!std::regex_search(lines[j].text, m, units_re)) {
        if (std::regex_search(lines[j].text, m, named_units_re))
          fail(path, lines[j].number, "unknown units '" + m[1].str() + "' (vines reads g, gal, cm/s2, m/s2)");
        continue;
      }
      const char c0 = static_cast<char>(std::tolower(static_cast<unsigned char>(m[1].str()[0])));
      h.units = m[1].length() == 1 ? Units::kG : c0 == 'm' ? Units::kMps2 : Units::kCmps2;
    }
    return h;
  }
  return std::nullopt;
}

// ---- parsed record before unit conversion ----

struct Raw {
  std::vector<double> values;
  double dt = 0.0;
  double t0 = 0.0;
  Units units = Units::kG;
};

Raw parse_at2(const std::vector<Line>& lines, const At2Header& h, const RecordSpec& spec) {
  Raw raw{{}, h.dt, 0.0, h.units.value_or(spec.units)};
  raw.values.reserve(std::min<std::size_t>(h.npts, 1u << 20));
  for (std::size_t i = h.line_index + 1; i < lines.size(); ++i) {
    for (auto tok : tokens(lines[i].text, false)) {
      raw.values.push_back(parse_number(tok, spec.path, lines[i].number));
    }
  }
  if (raw.values.size() != h.npts) {
    fail(spec.path, lines[h.line_index].number,
         "NPTS=" + std::to_string(h.npts) + " in the header but " +
             std::to_string(raw.values.size()) + " values read");
  }
  return raw;
}

// Acceleration values only, any count per line; dt comes from the spec.
Raw parse_accel(const std::vector<Line>& lines, const RecordSpec& spec) {
  if (!(spec.dt_s > 0.0) || !std::isfinite(spec.dt_s)) {
    fail(spec.path, "accel-only record needs dt > 0, got dt = " + fmt(spec.dt_s));
  }
  Raw raw{{}, spec.dt_s, 0.0, spec.units};
  for (const Line& l : lines) {
    for (auto tok : tokens(l.text, true)) {
      raw.values.push_back(parse_number(tok, spec.path, l.number));
    }
  }
  if (raw.values.empty()) fail(spec.path, "no samples");
  return raw;
}

// A table of numbers with the same column count on every non-comment line.
struct Table {
  std::vector<std::vector<double>> rows;
  std::vector<std::size_t> line_numbers;
  std::size_t columns = 0;
};

Table parse_table(const std::vector<Line>& lines, const std::string& path) {
  Table t;
  for (const Line& l : lines) {
    const auto toks = tokens(l.text, true);
    if (toks.empty()) continue;
    if (t.columns == 0) t.columns = toks.size();
    if (toks.size() != t.columns) {
      fail(path, l.number,
           "expected " + std::to_string(t.columns) + " columns, found " +
               std::to_string(toks.size()));
    }
    std::vector<double> row;
    row.reserve(toks.size());
    for (auto tok : toks) row.push_back(parse_number(tok, path, l.number));
    t.rows.push_back(std::move(row));
    t.line_numbers.push_back(l.number);
  }
  if (t.rows.empty()) fail(path, "no samples");
  return t;
}

// Time column plus acceleration columns; the time must be increasing and uniform.
Raw parse_time_accel(const Table& t, const RecordSpec& spec) {
  const std::string& path = spec.path;
  if (t.columns < 2) fail(path, t.line_numbers[0], "time/accel record needs at least 2 columns");
  if (spec.column < 1 || static_cast<std::size_t>(spec.column) >= t.columns) {
    fail(path, t.line_numbers[0],
         "column " + std::to_string(spec.column) + " out of range: the file has " +
             std::to_string(t.columns - 1) + " acceleration column(s)");
  }
  const std::size_t n = t.rows.size();
  if (n < 2) fail(path, t.line_numbers[0], "a time column needs at least 2 samples to give dt");

  // dt from the end points; each step and each time must sit on the uniform grid.
  const double t0 = t.rows.front()[0];
  const double dt = (t.rows.back()[0] - t0) / static_cast<double>(n - 1);
  const double tol = kTimeTolerance * dt;
  for (std::size_t i = 1; i < n; ++i) {
    const double step = t.rows[i][0] - t.rows[i - 1][0];
    if (!(step > 0.0)) {
      fail(
          path, t.line_numbers[i],
          "time does not increase (" + fmt(t.rows[i][0]) + " after " + fmt(t.rows[i - 1][0]) + ")");
    }
    const double grid = t0 + static_cast<double>(i) * dt;
    if (std::abs(step - dt) > tol || std::abs(t.rows[i][0] - grid) > tol) {
      fail(path, t.line_numbers[i],
           "non-uniform time step " + fmt(step) + " (record dt " + fmt(dt) + ")");
    }
  }

  Raw raw{{}, dt, t0, spec.units};
  raw.values.reserve(n);
  for (const auto& row : t.rows) raw.values.push_back(row[static_cast<std::size_t>(spec.column)]);
  return raw;
}

// A record's dt must be in [kMinRecordDt, kMaxRecordDt].
void check_dt(const std::string& path, double dt) {
  if (!(std::isfinite(dt) && dt >= kMinRecordDt && dt <= kMaxRecordDt)) {
    fail(path, "dt " + fmt(dt) + " s is outside [" + fmt(kMinRecordDt) + ", " + fmt(kMaxRecordDt) +
                   "] s");
  }
}

// Points, dt and end time of a record within the limits. A few bytes must
// not ask for days of samples (found by record_fuzz: a huge DT or a time
// column that starts late; the run would simulate it all).
void check_extent(const std::string& path, std::size_t points, double dt, double t0) {
  check_count(path, points, "points");
  // One rule in every format: a record is at least two points (one interval).
  if (points < 2) fail(path, "a record needs at least 2 points, it has " + std::to_string(points));
  check_dt(path, dt);
  const double end_s = t0 + dt * static_cast<double>(points);
  if (!(end_s <= kMaxRecordEndS)) {
    fail(path, "the record ends at t = " + fmt(end_s) + " s, later than the " + fmt(kMaxRecordEndS) +
                   " s a record may last (check DT or the time column)");
  }
}

// A file forced to "accel" whose rows are all of two or more columns, the
// first rising by one step: a time column, which would be read as
// accelerations.
void refuse_time_column(const std::vector<Line>& lines, const std::string& path) {
  Table t;
  try {
    t = parse_table(lines, path);
  } catch (const RecordError&) {
    return;  // ragged rows or not numbers: not a table (parse_accel says what is wrong)
  }
  if (t.columns < 2 || t.rows.size() < 3) return;
  const double step = t.rows[1][0] - t.rows[0][0];
  if (!(step > 0)) return;
  for (std::size_t i = 1; i < t.rows.size(); ++i)
    if (std::abs(t.rows[i][0] - t.rows[i - 1][0] - step) > 1e-6 * std::max(step, std::abs(t.rows[i][0]))) return;
  const std::size_t columns = t.columns;
  fail(path, "format accel, but every row has " + std::to_string(columns) +
                 " columns and the first rises by " + fmt(step) +
                 " each row: a time column (use format \"time-accel\", or \"auto\")");
}

// ---- from_lines: pick the format, parse, convert to m/s^2 ----

Record from_lines(const std::vector<Line>& lines, const RecordSpec& spec) {
  if (!std::isfinite(spec.scale)) fail(spec.path, "scale must be finite");
  Raw raw;
  const bool maybe_at2 = spec.format == RecordFormat::kAuto || spec.format == RecordFormat::kAt2;
  const auto header = maybe_at2 ? find_at2_header(lines, spec.path) : std::nullopt;
  if (header) {
    raw = parse_at2(lines, *header, spec);
  } else if (spec.format == RecordFormat::kAt2) {
    fail(spec.path, "no 'NPTS= .., DT= ..' header line in the first " +
                        std::to_string(kHeaderSearchLines) + " lines");
  } else if (spec.format == RecordFormat::kAccel) {
    refuse_time_column(lines, spec.path);
    raw = parse_accel(lines, spec);
  } else {
    // Time/accel, or (auto) a single column of accelerations.
    const Table table = parse_table(lines, spec.path);
    raw = (spec.format == RecordFormat::kAuto && table.columns == 1)
              ? parse_accel(lines, spec)
              : parse_time_accel(table, spec);
  }
  check_extent(spec.path, raw.values.size(), raw.dt, raw.t0);

  Record rec;
  rec.path = spec.path;
  rec.dt_s = raw.dt;
  rec.t0_s = raw.t0;
  const double factor = unit_factor(raw.units) * spec.scale;
  rec.accel_mps2.reserve(raw.values.size());
  for (double v : raw.values) rec.accel_mps2.push_back(v * factor);
  return rec;
}

}  // namespace

// ---- load_record / parse_record: a file, or its text already in memory ----

Record load_record(const RecordSpec& spec) {
  return from_lines(read_lines(spec.path), spec);
}

Record parse_record(const std::string& text, const RecordSpec& spec) {
  return from_lines(split_lines(text, spec.path), spec);
}

// ---- detection: what kAuto reads the file as ----

RecordFormat detect_record_format(const std::string& path) {
  const std::vector<Line> lines = read_lines(path);
  if (find_at2_header(lines, path)) return RecordFormat::kAt2;
  for (const Line& l : lines) {
    const auto toks = tokens(l.text, true);
    if (!toks.empty()) return toks.size() == 1 ? RecordFormat::kAccel : RecordFormat::kTimeAccel;
  }
  fail(path, "no samples");
}

double Record::pga_mps2() const {
  double peak = 0.0;
  for (double a : accel_mps2) peak = std::max(peak, std::abs(a));
  return peak;
}

double unit_factor(Units u) {
  switch (u) {
    case Units::kG: return kG;
    case Units::kMps2: return 1.0;
    case Units::kCmps2: return 0.01;
  }
  return 1.0;
}

void check_record(const Record& record) {
  if (record.accel_mps2.empty()) fail(record.path, "no samples");
  check_extent(record.path, record.accel_mps2.size(), record.dt_s, record.t0_s);
  for (std::size_t i = 0; i < record.accel_mps2.size(); ++i)
    if (!std::isfinite(record.accel_mps2[i])) fail(record.path, "sample " + std::to_string(i) + " is not finite");
}

}  // namespace vines::hal
