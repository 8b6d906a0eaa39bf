// Host HAL backend: input files (records, scenes, study specs) read whole,
// only when they are regular files of bounded size (record.hpp).
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "host/record.hpp"

namespace vines::hal {

// ---- input files: regular, bounded, read whole ----

std::string read_input_file(const std::string& path, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  auto refuse = [&](const std::string& why) { throw std::runtime_error(path + ": " + why); };
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) refuse("file not found");
  if (ec) refuse("cannot access file: " + ec.message());
  if (st.type() == fs::file_type::directory) refuse("is a directory, not a file");
  if (st.type() != fs::file_type::regular) {
    refuse("not a regular file (a device, FIFO or socket): only files on disk are read");
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) refuse("cannot access file: " + ec.message());
  if (size > max_bytes) {
    refuse("file of " + std::to_string(size) + " bytes: larger than the " + std::to_string(max_bytes) +
           " bytes an input may have");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse(std::string("cannot open file for reading: ") + std::strerror(errno));
  // One byte more than measured: reading it means the file grew while read.
  std::string content(static_cast<std::size_t>(size) + 1, '\0');
  in.read(content.data(), static_cast<std::streamsize>(content.size()));
  if (in.bad()) refuse("read error");
  content.resize(static_cast<std::size_t>(in.gcount()));
  if (content.size() > size) refuse("changed while it was read");
  return content;
}

}  // namespace vines::hal
