#!/usr/bin/env bash
# Installs the Debian 12 packages of a set (default: all):
#   build  what the `vines` program needs to compile: the compiler, CMake,
#          the headers it compiles against, TBB
#   plots  the plot scripts' Python libraries
#   main   build and plots: what tools/main.sh needs (it installs plots
#          while it compiles)
#   all    main plus the tests and benchmarks, the CVODE baseline (SUNDIALS),
#          the Python package (pybind11) and pytest, MPI, the libFuzzer
#          targets, the Cortex-M4F/M7 cross toolchain and QEMU for the MCU
#          images (tools/test.sh, CI).
# Installs only what is missing, so it is cheap to re-run.
# Root or sudo; no questions asked (usable with no stdin, as in CI).
# Usage: bash tools/setup.sh [build|plots|main|all]
set -euo pipefail

build=(
  cmake make g++                                 # host build
  libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev
  libcli11-dev                                   # the vines command line
  libtbb-dev                                     # the parallel map of sweep, design, stress
  libmicrohttpd-dev pkg-config                   # the monitoring page (vines hil --serve, view)
)
plots=(
  python3-matplotlib python3-numpy               # plots: use /usr/bin/python3
)
rest=(
  libgtest-dev libgmock-dev libbenchmark-dev     # tests, benchmarks
  libcpp-httplib-dev                             # the page's tests' HTTP client
  libsundials-dev                                # CVODE baseline (vines bench, tests)
  pybind11-dev python3-dev python3-pytest        # the Python package and its tests,
  mypy python3-pandas                            # its typing (mypy --strict), DataFrames
  python3-venv python3-pip                       # its `pip install .` test,
  python3-nbclient python3-ipykernel             # the notebook examples/paper.ipynb
  python3-scipy                                  # the twin bound's VI NES part (matrix exponential)
  openmpi-bin libopenmpi-dev                     # vines sweep across MPI ranks
  clang libclang-rt-14-dev                       # libFuzzer target of the link decoder
  gcc-arm-none-eabi libnewlib-arm-none-eabi      # cortex-m4f, cortex-m7 presets
  libstdc++-arm-none-eabi-newlib                 # C++ headers/libs for it
  qemu-system-arm                                # runs the MCU images (ctest)
  socat                                          # a pseudo-terminal pair: the serial node's test
  chromium                                       # the monitoring page's browser test
)

if (($# > 1)); then
  echo "usage: bash tools/setup.sh [build|plots|main|all]" >&2
  exit 2
fi
set_name=${1:-all}
case $set_name in
  build) packages=("${build[@]}") ;;
  plots) packages=("${plots[@]}") ;;
  main) packages=("${build[@]}" "${plots[@]}") ;;
  all) packages=("${build[@]}" "${plots[@]}" "${rest[@]}") ;;
  *)
    echo "setup: unknown package set '$set_name' (build, plots, main or all)" >&2
    echo "usage: bash tools/setup.sh [build|plots|main|all]" >&2
    exit 2
    ;;
esac

# Node.js and npm for the browser test (puppeteer-core), Debian's unless a
# node with npm is there already (NodeSource's nodejs holds npm and
# conflicts with Debian's npm package).
if [[ $set_name == all ]] && ! { command -v node && command -v npm; } >/dev/null; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  # Same test as `dpkg -s`, but "removed, config files left" counts as missing.
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -qx 'install ok installed' ||
    missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages of set '$set_name' are installed"
  exit 0
fi

echo "setup ($set_name): installing ${missing[*]}"
sudo=()
if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
# An install stopped half way (packages unpacked, not configured) makes every
# apt-get install refuse ("dpkg was interrupted"): finish it first (no-op
# otherwise).
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive dpkg --configure -a </dev/null
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q </dev/null
# --force-unsafe-io: dpkg does not fsync every file it unpacks (as in Debian's
# container images); on a fresh machine that is most of the install's time. A
# power cut during the install means running it again.
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -q --no-install-recommends -o Dpkg::Options::=--force-unsafe-io "${missing[@]}" </dev/null
