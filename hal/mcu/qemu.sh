#!/usr/bin/env bash
# Runs a bare-metal image on an emulated MPS2 board; the image's exit status
# (semihosting SYS_EXIT_EXTENDED) is this script's. ctest uses it as
# CMAKE_CROSSCOMPILING_EMULATOR (cmake/arm-none-eabi.cmake).
#   qemu.sh BOARD IMAGE.elf [QEMU_OPTION...]
# BOARD: a QEMU machine (hal/mcu/boards.txt's; mps2-an385, a Cortex-M3
# without FPU, for the fixed-point image). Extra options go
# to QEMU (e.g. -serial file:OUT, -icount shift=0); without a -serial option,
# UART0 is not connected. Semihosting output goes to stderr. The run is
# killed after VINES_QEMU_TIMEOUT seconds (default 600).
set -uo pipefail
if (($# < 2)); then
  echo "usage: qemu.sh BOARD IMAGE.elf [QEMU_OPTION...]" >&2
  exit 2
fi
board=$1 image=$2
shift 2
if [[ ! -f $image ]]; then
  echo "qemu.sh: $image: no such image (build it first)" >&2
  exit 2
fi
if ! command -v qemu-system-arm >/dev/null; then
  echo "qemu.sh: qemu-system-arm not found: install it (bash tools/setup.sh)" >&2
  exit 2
fi
if ! qemu-system-arm -machine help | awk '{print $1}' | grep -qxF -- "$board"; then
  echo "qemu.sh: unknown board '$board': not a machine of qemu-system-arm (qemu-system-arm -machine help)" >&2
  exit 2
fi
serial=(-serial null)
for a in "$@"; do
  if [[ $a == -serial || $a == -chardev ]]; then serial=(); fi
done
limit=${VINES_QEMU_TIMEOUT:-600}
timeout --kill-after=5 "$limit" qemu-system-arm -M "$board" -display none -monitor none \
  -semihosting-config enable=on,target=native "${serial[@]}" -kernel "$image" "$@"
rc=$?
if ((rc == 124 || rc == 137)); then
  echo "qemu.sh: $image on $board did not finish within ${limit} s (VINES_QEMU_TIMEOUT)" >&2
fi
exit $rc
