#!/usr/bin/env bash
# Work-precision benchmark: every El Centro scene, both scalars, sensor rates
# and contact sub-step tolerances swept, DOP853 in double (tuned, and the
# reference's driver) and SUNDIALS CVODE (Adams, BDF) as the baselines, all
# against data/reference. Writes out/bench/bench.csv, prints the table, plots
# out/bench/work_precision.png (error against wall time) and writes the table,
# stamped, to docs/figures/bench.md (tools/figures.py).
# Options are passed on to `vines bench` (e.g. --min-time 1).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

cmake --preset release >/dev/null
cmake --build --preset release -j2 --target vines
mkdir -p out/bench
build/release/vines bench data/scenes/elcentro_*.toml --scalars double,float \
  --rates 50,200,1000,5000 --rtols 1e-6,1e-7,1e-8,1e-10,1e-12 --csv out/bench/bench.csv "$@"
/usr/bin/python3 tools/plot_bench.py out/bench/bench.csv --out out/bench/work_precision.png
/usr/bin/python3 tools/figures.py bench out/bench/bench.csv --command "bash tools/bench.sh${*:+ $*}"
