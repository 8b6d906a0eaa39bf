#!/usr/bin/env bash
# The project's test command. Host: build and run the unit tests (preset
# release). MCU: build the Cortex-M4F image (preset cortex-m4f; the build also
# proves that the link refuses the heap) and, when qemu-system-arm is
# installed, run the smoke image on the emulated MPS2-AN386 board.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/setup.sh

cmake --preset release
cmake --build --preset release -j2
ctest --preset release

cmake --preset cortex-m4f
cmake --build --preset cortex-m4f -j2
if command -v qemu-system-arm >/dev/null; then
  cmake --build --preset cortex-m4f --target vines_mcu_smoke_qemu
else
  echo "test.sh: qemu-system-arm not installed: MCU image built, not run" >&2
fi
echo "test.sh: all passed"
