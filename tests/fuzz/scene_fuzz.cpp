// libFuzzer target: the scene parser (sim_host/scene/scene.cpp on Debian's toml++
// library, as the program runs it) on arbitrary text. A SceneError (a refusal,
// TOML syntax errors included) is fine; any other exception, crash, sanitizer
// report or hang is a finding.
// Built by tests/CMakeLists.txt with clang -fsanitize=fuzzer,address,undefined;
// run by CTest as scene_fuzz.
#include <cstdint>
#include <string>

#include "sim_host/scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)vines::host::parse_scene(text, "fuzz.toml");
  } catch (const vines::host::SceneError&) {
    // refused with a message: fine
  }
  return 0;
}
