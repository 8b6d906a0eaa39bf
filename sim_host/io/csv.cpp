#include "sim_host/io/csv.hpp"

#include <charconv>
#include <cstdio>
#include <cstring>

namespace vines::host {

CsvWriter::CsvWriter(const std::string& path) : file_(path) {}

// ---- cells ----
CsvWriter& CsvWriter::text(const std::string& s) {
  return s.find_first_of(",\"\r\n") == std::string::npos ? raw(s) : quoted(s);
}

CsvWriter& CsvWriter::quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  q += '"';
  return raw(q);
}

CsvWriter& CsvWriter::raw(const std::string& s) {
  separate();
  put(s.data(), s.size());
  return *this;
}

// "%.<precision>f", "%.<precision>g" and "%.<precision>e" by std::to_chars,
// which writes what printf writes for them (C locale) in a fraction of its
// time: a timeseries.csv is some 274,000 numbers. Any other format by
// snprintf.
int format_number(char* buf, std::size_t size, double v, const char* format) {
  const std::size_t len = std::strlen(format);
  if (len >= 4 && len <= 5 && format[0] == '%' && format[1] == '.') {
    int precision = 0;
    bool digits = true;
    for (std::size_t i = 2; i + 1 < len; ++i) {
      digits = digits && format[i] >= '0' && format[i] <= '9';
      precision = precision * 10 + (format[i] - '0');
    }
    const char kind = format[len - 1];
    if (digits && (kind == 'f' || kind == 'g' || kind == 'e')) {
      const std::chars_format style = kind == 'f'   ? std::chars_format::fixed
                                      : kind == 'g' ? std::chars_format::general
                                                    : std::chars_format::scientific;
      const auto r = std::to_chars(buf, buf + size, v, style, precision);
      if (r.ec == std::errc()) return static_cast<int>(r.ptr - buf);
    }
  }
  return std::snprintf(buf, size, format, v);
}

CsvWriter& CsvWriter::number(double v, const char* format) {
  char buf[512];  // "%.99f" of the largest double fits
  int n = format_number(buf, sizeof buf, v, format);
  separate();
  if (n >= 0 && static_cast<std::size_t>(n) < sizeof buf) {
    put(buf, static_cast<std::size_t>(n));
  } else {  // a longer printf format: its whole text
    std::string big(n > 0 ? static_cast<std::size_t>(n) + 1 : 0, '\0');
    n = n > 0 ? std::snprintf(big.data(), big.size(), format, v) : 0;
    put(big.data(), static_cast<std::size_t>(n > 0 ? n : 0));
  }
  return *this;
}

CsvWriter& CsvWriter::exact(double v) {
  char buf[32];  // the longest shortest form, "-2.2250738585072014e-308", is 24
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  separate();
  put(buf, static_cast<std::size_t>(r.ptr - buf));
  return *this;
}

CsvWriter& CsvWriter::integer(long long v) { return raw(std::to_string(v)); }

CsvWriter& CsvWriter::empty() { return raw(""); }

void CsvWriter::end_row() {
  row_ += '\n';
  file_.write(row_.data(), row_.size());
  row_.clear();
  first_ = true;
}

// ---- checked output ----
void CsvWriter::close() {
  if (!row_.empty()) file_.write(row_.data(), row_.size());
  row_.clear();
  file_.commit();
}

// A row is gathered, then written at once.
void CsvWriter::put(const char* s, std::size_t n) { row_.append(s, n); }

void CsvWriter::separate() {
  if (!first_) put(",", 1);
  first_ = false;
}

}  // namespace vines::host
