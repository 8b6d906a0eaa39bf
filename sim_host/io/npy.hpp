// A NumPy .npy file (format version 1.0) of one record per row: a structured
// array of named little-endian float64 or int32 fields, as numpy.load reads
// it (numpy.lib.format). Every value is written as its bytes, so it reads
// back bit for bit. The write is checked and atomic (output.hpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim_host/io/output.hpp"

namespace vines::host {

struct NpyField {
  std::string name;
  bool integer = false;  // int32 ('<i4'), else float64 ('<f8')
};

class NpyWriter {
 public:
  // Starts the file's temporary copy with the header for `rows` rows.
  NpyWriter(const std::string& path, const std::vector<NpyField>& fields, std::size_t rows);

  // One row: a value per field, in order (integer fields rounded to int32).
  void row(const double* values);
  // Puts the file in place; throws if anything could not be written or the
  // rows written are not the rows announced.
  void close();

 private:
  AtomicFile file_;
  std::vector<NpyField> fields_;
  std::size_t rows_, written_ = 0;
  std::string path_, buf_;
};

}  // namespace vines::host
