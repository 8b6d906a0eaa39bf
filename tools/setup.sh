#!/usr/bin/env bash
# Installs the Debian 12 packages the project needs: host build and tests,
# the Cortex-M4F and M7 cross builds, QEMU for the MCU images, and the plot script's
# Python libraries. Installs only what is missing, so it is cheap to re-run.
# Root or sudo; no questions asked (usable with no stdin, as in CI).
set -euo pipefail

packages=(
  cmake make g++                                 # host build
  libgtest-dev libgmock-dev libbenchmark-dev     # tests, benchmarks
  libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev
  libcli11-dev                                   # the vines command line
  gcc-arm-none-eabi libnewlib-arm-none-eabi      # cortex-m4f, cortex-m7 presets
  libstdc++-arm-none-eabi-newlib                 # C++ headers/libs for it
  qemu-system-arm                                # runs the MCU images (ctest)
  python3-matplotlib python3-numpy               # plots: use /usr/bin/python3
  openmpi-bin libopenmpi-dev                     # vines sweep across MPI ranks
  libsundials-dev                                # CVODE baseline (vines reference, tests)
  libtbb-dev                                     # the parallel map of sweep, design, stress
  clang libclang-rt-14-dev                       # libFuzzer target of the link decoder
)

missing=()
for p in "${packages[@]}"; do
  # Same test as `dpkg -s`, but "removed, config files left" counts as missing.
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -qx 'install ok installed' ||
    missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages are installed"
  exit 0
fi

echo "setup: installing ${missing[*]}"
sudo=()
if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q </dev/null
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -q --no-install-recommends "${missing[@]}" </dev/null
