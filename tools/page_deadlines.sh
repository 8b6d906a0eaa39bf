#!/usr/bin/env bash
# The bench's deadline figures with and without the monitoring page open
# (issue 37; docs/hil.md, "The monitoring page"): `vines hil` of the El
# Centro VI NES scene in real time for SECONDS, without --serve, with
# --serve and no client, with a client reading the event stream without
# drawing it, and with the page open in headless chromium, ROUNDS rounds
# interleaved (tests/browser/deadlines.js). Writes the runs to
# out/page_deadlines.jsonl and the table, stamped, to
# docs/figures/page_deadlines.md (tools/figures.py). Needs chromium and
# node with npm (bash tools/setup.sh all).
# Usage: bash tools/page_deadlines.sh [SECONDS [ROUNDS]]   (default 20 3)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
seconds=${1:-20} rounds=${2:-3}
cmake --preset release >/dev/null
cmake --build --preset release -j2 --target vines
mkdir -p out
bash tests/browser_test.sh build/release/vines . build/release tests/browser/deadlines.js \
  build/release/vines data/scenes/elcentro_vines.toml "$seconds" "$rounds" | tee out/page_deadlines.jsonl
/usr/bin/python3 tools/figures.py deadlines out/page_deadlines.jsonl \
  --command "bash tools/page_deadlines.sh $seconds $rounds"
