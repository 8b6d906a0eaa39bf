// libFuzzer target: the record reader (hal/host/record.cpp) on arbitrary text,
// in every format. The first byte picks the options, the rest is the file's
// text: bits 0-1 the format (auto, at2, time-accel, accel), bits 2-3 the units,
// bits 4-5 the acceleration column (1..4), bits 6-7 the dt of values-only
// records (0.01, 0.005, 0: refused, 1e-300). A record that loads is resampled
// at 200 Hz, as a run does. A RecordError (a refusal) is fine; any other
// exception, crash, sanitizer report or hang is a finding.
// Built by tests/CMakeLists.txt with clang -fsanitize=fuzzer,address,undefined;
// run by CTest as record_fuzz.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "host/record.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using vines::hal::RecordFormat;
  using vines::hal::Units;
  if (size == 0) return 0;
  // The options byte.
  const unsigned o = data[0];
  static constexpr RecordFormat kFormats[] = {RecordFormat::kAuto, RecordFormat::kAt2,
                                              RecordFormat::kTimeAccel, RecordFormat::kAccel};
  static constexpr Units kUnits[] = {Units::kG, Units::kMps2, Units::kCmps2, Units::kG};
  static constexpr double kDt[] = {0.01, 0.005, 0.0, 1e-300};
  vines::hal::RecordSpec spec;
  spec.path = "fuzz.at2";
  spec.format = kFormats[o & 3u];
  spec.units = kUnits[(o >> 2) & 3u];
  spec.column = 1 + static_cast<int>((o >> 4) & 3u);
  spec.dt_s = kDt[(o >> 6) & 3u];

  // The text: parse, then resample what loaded; every sample must be finite.
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    const vines::hal::Record rec = vines::hal::parse_record(text, spec);
    for (double a : vines::hal::resample(rec, 200.0))
      if (!std::isfinite(a)) std::abort();  // a loaded record gave a non-finite sample
  } catch (const vines::hal::RecordError&) {
    // refused with a message: fine
  }
  return 0;
}
