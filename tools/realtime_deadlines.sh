#!/usr/bin/env bash
# The bench's deadline figures with and without real-time service (issue 55;
# docs/hil.md, "Real-time service"): `vines hil` of the El Centro VI NES
# scene in real time for SECONDS, time-shared and with --realtime-priority 80
# --cpus 0,1 (SCHED_FIFO and locked memory for the bench and its node, each
# on its own core), ROUNDS rounds interleaved. Writes the runs to
# out/realtime_deadlines.jsonl and the table, stamped, to
# docs/figures/realtime_deadlines.md (tools/figures.py). Run it on an idle
# machine: the figures are the machine's as much as the program's.
# Usage: bash tools/realtime_deadlines.sh [SECONDS [ROUNDS]]   (default 20 3)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
seconds=${1:-20} rounds=${2:-3}
cmake --preset release >/dev/null
cmake --build --preset release -j2 --target vines
mkdir -p out
runs=out/realtime_deadlines.jsonl
: > "$runs"
for round in $(seq 1 "$rounds"); do
  for kind in "time-shared" "real-time service"; do
    service=()
    if [[ $kind != time-shared ]]; then service=(--realtime-priority 80 --cpus 0,1); fi
    load=$(cut -d' ' -f1 /proc/loadavg)
    build/release/vines hil data/scenes/elcentro_vines.toml --realtime --duration "$seconds" --json \
      --accept-degraded "${service[@]}" |
      /usr/bin/python3 -c '
import json, sys
r = json.load(sys.stdin)
print(json.dumps({"kind": sys.argv[1], "round": int(sys.argv[2]), "load": float(sys.argv[3]), "steps": r["steps"],
                  "deadline_misses": r["deadline_misses"], "latency_us": r["latency_us"],
                  "service": r.get("realtime_service")}))' "$kind" "$round" "$load" >> "$runs"
    echo "realtime_deadlines: $kind, round $round: $(tail -1 "$runs" | cut -c1-160)"
  done
done
/usr/bin/python3 tools/figures.py realtime "$runs" --command "bash tools/realtime_deadlines.sh $seconds $rounds"
