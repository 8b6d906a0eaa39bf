#include "sim_host/io/npy.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace vines::host {

NpyWriter::NpyWriter(const std::string& path, const std::vector<NpyField>& fields, std::size_t rows)
    : file_(path), fields_(fields), rows_(rows), path_(path) {
  static_assert(sizeof(double) == 8, "float64 fields");
  // Header: magic, version 1.0, its length, then the dict in Python syntax,
  // padded with spaces and a newline so the data start at a multiple of 64.
  std::string dict = "{'descr': [";
  for (const NpyField& f : fields) dict += "('" + f.name + "', '" + (f.integer ? "<i4" : "<f8") + "'), ";
  dict += "], 'fortran_order': False, 'shape': (" + std::to_string(rows) + ",), }";
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  if (dict.size() > 65535) throw std::runtime_error(path + ": too many columns for a .npy header");
  const char magic[8] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0};
  const unsigned char len[2] = {static_cast<unsigned char>(dict.size() & 0xff),
                                static_cast<unsigned char>(dict.size() >> 8)};
  file_.write(magic, sizeof magic);
  file_.write(reinterpret_cast<const char*>(len), 2);
  file_.write(dict);
  std::size_t row_bytes = 0;
  for (const NpyField& f : fields) row_bytes += f.integer ? 4 : 8;
  buf_.resize(row_bytes);
}

// The values' bytes, little-endian (the host's order: x86-64 and Arm Linux),
// gathered in a row's buffer and written at once.
void NpyWriter::row(const double* values) {
  char* p = buf_.data();
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    if (fields_[i].integer) {
      const std::int32_t v = static_cast<std::int32_t>(std::lround(values[i]));
      std::memcpy(p, &v, 4);
      p += 4;
    } else {
      std::memcpy(p, &values[i], 8);
      p += 8;
    }
  }
  file_.write(buf_.data(), buf_.size());
  ++written_;
}

void NpyWriter::close() {
  if (written_ != rows_)
    throw std::runtime_error(path_ + ": " + std::to_string(written_) + " rows written, " + std::to_string(rows_) +
                             " announced");
  file_.commit();
}

}  // namespace vines::host
