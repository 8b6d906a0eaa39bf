#include "sim_host/monitor/http_parse.hpp"

#include <algorithm>
#include <stdexcept>

namespace vines::host::monitor {

Address parse_address(const std::string& option, const std::string& value) {
  Address a;
  std::string port = value;
  if (!value.empty() && value[0] == '[') {  // [IPv6]:PORT
    const std::size_t close = value.find(']');
    if (close == std::string::npos || close + 1 >= value.size() || value[close + 1] != ':' || close == 1)
      throw std::invalid_argument(option + " " + value + ": expected [IPV6]:PORT, e.g. [::1]:8080");
    a.host = value.substr(1, close - 1);
    port = value.substr(close + 2);
  } else if (value.find(':') != value.rfind(':')) {
    throw std::invalid_argument(option + " " + value + ": an IPv6 address goes in brackets, [ADDRESS]:PORT, e.g. [::1]:8080");
  } else if (const std::size_t colon = value.rfind(':'); colon != std::string::npos) {
    a.host = value.substr(0, colon);
    port = value.substr(colon + 1);
    if (a.host.empty()) throw std::invalid_argument(option + " " + value + ": no host before ':' (HOST:PORT or PORT)");
  }
  // A port: digits only, 0 to 65535.
  const bool digits = !port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos;
  if (!digits || std::stol(port) > 65535)
    throw std::invalid_argument(option + " " + value + ": '" + port +
                                "' is not a port (0 to 65535; 0: any free one); expected [HOST:]PORT");
  a.port = static_cast<int>(std::stol(port));
  return a;
}

bool parse_byte_range(const std::string& v, std::size_t size, std::size_t* from, std::size_t* to) {
  if (v.rfind("bytes=", 0) != 0 || size == 0) return false;
  const std::string r = v.substr(6);
  const std::size_t dash = r.find('-');
  if (dash == std::string::npos || r.find_first_not_of("0123456789-") != std::string::npos || r.size() > 40) return false;
  const std::string a = r.substr(0, dash), b = r.substr(dash + 1);
  if ((a.empty() && b.empty()) || a.size() > 18 || b.size() > 18 || b.find('-') != std::string::npos)
    return false;  // one dash; stoull cannot overflow
  if (a.empty()) {  // the last N bytes
    const std::size_t n = std::stoull(b);
    if (n == 0) return false;
    *from = n >= size ? 0 : size - n, *to = size - 1;
    return true;
  }
  *from = std::stoull(a);
  *to = b.empty() ? size - 1 : std::min<std::size_t>(std::stoull(b), size - 1);
  return *from < size && *from <= *to;
}

}  // namespace vines::host::monitor
