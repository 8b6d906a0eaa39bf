// One CSV writer for the files the commands write (sweep results.csv, run
// timeseries.csv, bench --csv, hil --csv): comma-separated cells, one row a line; a
// text cell is quoted when it holds a comma, a quote or a line break (quotes
// doubled, RFC 4180), or always with quoted(); numbers in a printf format or
// exact (shortest round trip).
// Writes are checked and atomic (sim_host/io/output.hpp): the file appears, whole,
// at close(); a write that fails throws a std::runtime_error naming the file
// and the reason, and a writer dropped before close() leaves the old file as it was.
#pragma once

#include <string>

#include "sim_host/io/output.hpp"

namespace vines::host {

// A number in a printf format ("%.10g"), written to buf as snprintf would;
// returns its length.
int format_number(char* buf, std::size_t size, double v, const char* format);

class CsvWriter {
 public:
  explicit CsvWriter(const std::string& path);  // starts the file's temporary copy
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  CsvWriter& text(const std::string& s);    // quoted when it must be
  CsvWriter& quoted(const std::string& s);  // always quoted
  CsvWriter& raw(const std::string& s);     // as is (already CSV-safe)
  CsvWriter& number(double v, const char* format);  // e.g. "%.10g"
  CsvWriter& exact(double v);  // shortest text that reads back to v bit for bit
  CsvWriter& integer(long long v);
  CsvWriter& empty();                       // an empty cell
  void end_row();
  // Flushes, closes and puts the file in place; throws if anything could not be written.
  void close();

 private:
  void put(const char* s, std::size_t n);
  void separate();

  AtomicFile file_;
  std::string row_;    // the row being written
  bool first_ = true;  // no cell yet in this row
};

}  // namespace vines::host
