#!/usr/bin/env bash
# The shake-table (hybrid) mode's vRTHS criteria (docs/rths_criteria.md) over
# compensators x actuators x records: the last table of docs/hil.md, "Hybrid
# mode: statistics and the vRTHS criteria".
#
#   tools/hybrid_criteria.sh [VINES]     (VINES: the release build's vines)
#
# Compensators: none, poly (order 2), adaptive; both compensators know only
# the default actuator's delay (--comp-delay 16.64 ms: 5 ms + 2 zeta/w + h/2).
# Actuators: default (20 Hz, zeta 0.7, 5 ms), stiffer (40 Hz), softer
# (10 Hz), longer delay (10 ms). Records: El Centro (the scene's), Kobe KJMA
# and Northridge Rinaldi (record names found in the default ground-motion
# folder, as the scenes find theirs), VI NES; El Centro, TMD.
# Prints one markdown row per run: delay [ms], tracking RMS and peak [%],
# top-floor response RMS and peak [%].
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
vines=$(realpath "${1:-$root/build/release/vines}")
cd "$root"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The VI NES scene on another record (an AT2 file, units g).
scene_on() {
  sed -e "s|^name = .*|name = \"$1_vines\"|" -e "s|^path = .*|path = \"$2\"|" -e 's|^format = .*|format = "at2"|' \
    "$root/data/scenes/elcentro_vines.toml" > "$tmp/$1_vines.toml"
  echo "$tmp/$1_vines.toml"
}

scenes=("El Centro, VI NES=$root/data/scenes/elcentro_vines.toml"
        "Kobe, VI NES=$(scene_on kobe kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2)"
        "Northridge, VI NES=$(scene_on northridge northridge_1994_rinaldi_228_nga_rsn1063.at2)"
        "El Centro, TMD=$root/data/scenes/elcentro_tmd.toml")
actuators=("default=" "stiffer 40 Hz=--actuator-hz 40" "softer 10 Hz=--actuator-hz 10"
           "delay 10 ms=--actuator-delay 0.010")
comps=("none=--comp none" "poly2=--comp poly --comp-delay 0.01664" "adaptive=--comp adaptive --comp-delay 0.01664")

echo "| record, specimen | actuator | compensation | delay ms | tracking RMS % | tracking peak % | top response RMS % | top response peak % |"
echo "|---|---|---|---|---|---|---|---|"
for s in "${scenes[@]}"; do
  for a in "${actuators[@]}"; do
    for c in "${comps[@]}"; do
      # shellcheck disable=SC2086 # the options are words
      "$vines" hil "${s#*=}" --mode hybrid ${a#*=} ${c#*=} --json --accept-degraded |
        python3 -c '
import json, sys
h = json.load(sys.stdin)["hybrid"]
f = lambda v, p: "n/a" if v is None else p % v
print("| %s | %s | %s | %s | %s | %s | %s | %s |" % (sys.argv[1], sys.argv[2], sys.argv[3],
      f(h["tracking_delay_ms"], "%.3f"), f(h["tracking_rms_pct"], "%.3g"), f(h["tracking_peak_pct"], "%.3g"),
      f(h["response_rms_pct"][-1], "%.3g"), f(h["response_peak_pct"][-1], "%.3g")))' "${s%%=*}" "${a%%=*}" "${c%%=*}"
    done
  done
done
