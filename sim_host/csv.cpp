#include "sim_host/csv.hpp"

#include <cstdio>

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

CsvWriter& CsvWriter::number(double v, const char* format) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, format, v);
  separate();
  put(buf, static_cast<std::size_t>(n));
  return *this;
}

CsvWriter& CsvWriter::integer(long long v) { return raw(std::to_string(v)); }

CsvWriter& CsvWriter::empty() { return raw(""); }

void CsvWriter::end_row() {
  put("\n", 1);
  first_ = true;
}

// ---- checked output ----
void CsvWriter::close() { file_.commit(); }

void CsvWriter::put(const char* s, std::size_t n) { file_.write(s, n); }

void CsvWriter::separate() {
  if (!first_) put(",", 1);
  first_ = false;
}

}  // namespace vines::host
