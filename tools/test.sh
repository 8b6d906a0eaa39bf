#!/usr/bin/env bash
# The project's test command. Host: build and run the unit tests (preset
# release), then a subset of them under the sanitizers (presets debug and
# sanitize). MCU: for each board of hal/mcu/boards.txt (its preset), build the
# images (the build also proves that the link refuses the heap) and run the
# MCU tests in QEMU (ctest --preset <target>): the smoke image, the
# stack-overflow fault, the El Centro VI NES and TMD scenes fed over the UART
# and compared with the host build above, and the deadline monitor.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

start=$SECONDS
lap() { echo "test.sh: $1 at $((SECONDS - start)) s"; }

bash tools/setup.sh all
lap "packages ready"

cmake --preset release
cmake --build --preset release -j2
lap "release built"
ctest --preset release
lap "release tested"

# The host under AddressSanitizer and UBSan (preset sanitize: the debug
# preset's flags, with only the engines the subset runs): the subset labelled
# unit_sanitize (tests/README.md: which tests, why a subset, its time); any
# sanitizer report stops the test and fails it (halt_on_error in the preset).
cmake --preset sanitize
cmake --build --preset sanitize -j2 --target sanitize_tests
ctest --preset sanitize
lap "sanitizer subset tested"

for target in $(grep -oE '^[a-z0-9-]+ *\|' hal/mcu/boards.txt | tr -d ' |'); do
  cmake --preset "$target"
  cmake --build --preset "$target" -j2
  ctest --preset "$target"
  lap "$target tested"
done
echo "test.sh: all passed in $((SECONDS - start)) s"
