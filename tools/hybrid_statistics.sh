#!/usr/bin/env bash
# The shake-table (hybrid) mode judged as a chaotic specimen should be: by the
# paper's reductions x_r and E_r (against the bare frame) over a grid of the
# particle's initial conditions, hybrid against the pure simulation, rather
# than by one trajectory. docs/hil.md, "Hybrid mode: statistics and the vRTHS
# criteria".
#
#   tools/hybrid_statistics.sh [VINES]     (VINES: the release build's vines)
#
# El Centro, the VI NES scene at 1 kHz; 5 x 5 initial conditions (position
# -0.3 to 0.3 m of the 0.415 m free travel, velocity -0.4 to 0.4 m/s);
# actuators: the default (20 Hz, zeta 0.7, 5 ms delay, load cell noise) with
# adaptive compensation, and a near-ideal one (2 kHz, no delay, no noise,
# the command's one-step lag compensated). Prints one markdown row per
# actuator: mean +- sd of x_r and E_r [%], hybrid and pure, over the grid.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
vines=$(realpath "${1:-$root/build/release/vines}")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

actuators=("default, adaptive=--comp adaptive"
           "2 kHz, no delay, no noise=--actuator-hz 2000 --actuator-delay 0 --force-noise 0 --force-lsb 0 --comp poly --comp-delay 0.001")
echo "| actuator | runs | x_r hybrid % | x_r pure % | E_r hybrid % | E_r pure % |"
echo "|---|---|---|---|---|---|"
for a in "${actuators[@]}"; do
  : > "$tmp/rows"
  for x in -0.3 -0.15 0 0.15 0.3; do
    for v in -0.4 -0.2 0 0.2 0.4; do
      scene=$tmp/ic.toml
      sed -e "s|^beta = .*|&\ninitial_position_m = $x\ninitial_velocity_mps = $v|" \
        -e "s|^path = \"|path = \"$root/../shared/data/ground_motions/|" \
        "$root/data/scenes/elcentro_vines.toml" > "$scene"
      # shellcheck disable=SC2086 # the options are words
      "$vines" hil "$scene" --mode hybrid ${a#*=} --json --accept-degraded >> "$tmp/rows"
    done
  done
  python3 - "${a%%=*}" "$tmp/rows" <<'PY'
import json, statistics as st, sys
dec, text, rows = json.JSONDecoder(), open(sys.argv[2]).read(), []
i = 0
while i < len(text):
    if text[i].isspace():
        i += 1
        continue
    obj, i = dec.raw_decode(text, i)
    rows.append(obj["hybrid"])
def ms(key):
    v = [100 * r[key] for r in rows]
    return "%.1f +- %.1f" % (st.mean(v), st.stdev(v))
print("| %s | %d | %s | %s | %s | %s |" % (sys.argv[1], len(rows), ms("x_r_hybrid"), ms("x_r_pure"),
                                         ms("E_r_hybrid"), ms("E_r_pure")))
PY
done
