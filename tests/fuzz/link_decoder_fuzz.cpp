// libFuzzer target: the link decoder, every message decoder and the node state
// machine on arbitrary bytes (built with clang -fsanitize=fuzzer,address,undefined
// by tests/CMakeLists.txt; run by CTest as link_fuzz).
#include <cstdlib>

#include "fuzz/link_fuzz_body.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (vines::link::fuzz::run_one(data, size) != 0) std::abort();  // the node wrote a frame that does not decode
  return 0;
}
