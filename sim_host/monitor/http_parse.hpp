// What the page's server parses: the address it listens at (--serve) and a
// request's byte range.
#pragma once

#include <cstddef>
#include <string>

namespace vines::host::monitor {

// Where to listen: --serve [HOST:]PORT or [IPV6]:PORT (HOST 127.0.0.1 unless
// given).
struct Address {
  std::string host = "127.0.0.1";
  int port = 0;  // 0: any free port
};
// Parses [HOST:]PORT or [IPV6]:PORT; throws std::invalid_argument naming
// OPTION and VALUE (an IPv6 address without brackets too).
Address parse_address(const std::string& option, const std::string& value);

// A byte range of one file of `size` bytes: "bytes=A-B", "bytes=A-" or
// "bytes=-N" into [*from, *to]; false if it is none of these (numbers of
// more than 18 digits, a second dash) or outside the file.
bool parse_byte_range(const std::string& value, std::size_t size, std::size_t* from, std::size_t* to);

}  // namespace vines::host::monitor
