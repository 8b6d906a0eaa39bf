#!/usr/bin/env bash
# Thread and MPI scaling of `vines sweep`: one spec (default: the IC grid
# alone, the ic_vines study of data/studies/initial_conditions.toml) on 1 and 2
# threads and on 1, 2 and 3 MPI ranks of one thread each (when mpirun is
# there). Prints runs/s and the speedup of each, the serial fraction f that
# Amdahl's law gives from the 2-core speedup S (f = (1/S - 1/p) / (1 - 1/p)),
# the speedup it predicts on 8, 32 and 64 cores (1 / (f + (1 - f) / n)), and
# checks that every MPI run wrote the threaded results.csv byte for byte.
# Each figure is the best of VINES_SCALING_REPEATS runs (default 3): other
# work on the machine only slows a run down.
# usage: tools/scaling.sh [SPEC.toml] [VINES_BINARY]   (default build/release/vines)
set -euo pipefail
cd "$(dirname "$0")/.."
vines=${2:-build/release/vines}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
spec=${1:-}
if [[ -z $spec ]]; then
  # The IC grid alone: the ic_vines study of initial_conditions.toml, in a spec of its own.
  spec=data/studies/initial_conditions.toml
  /usr/bin/python3 - "$spec" "$tmp/ic_vines.toml" <<'EOF'
import os, re, sys
text = open(sys.argv[1]).read()
study = [s for s in re.split(r"(?m)^(?=\[\[study\]\])", text) if 'name = "ic_vines"' in s][0]
folder = os.path.dirname(os.path.abspath(sys.argv[1]))
open(sys.argv[2], "w").write(study.replace('scene = "../', 'scene = "%s/../' % folder))
EOF
  spec=$tmp/ic_vines.toml
fi

repeats=${VINES_SCALING_REPEATS:-3}
run() {  # run NAME [mpirun -n K] : the sweep `repeats` times, the best runs/s (from summary.json)
  local name=$1; shift
  for ((i = 0; i < repeats; ++i)); do
    "$@" "$vines" sweep "$spec" --threads "$threads" --out "$tmp/$name" --no-progress > "$tmp/$name.txt"
    /usr/bin/python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print(j["runs_per_s"], j["done"], j["wall_time_s"])' \
      "$tmp/$name/summary.json"
  done | sort -g -r | head -1
}

echo "scaling of vines sweep $spec ($(nproc) cores here)"
threads=1; read -r r1 n w1 < <(run t1)
threads=2; read -r r2 _ w2 < <(run t2)
cmp "$tmp/t1/results.csv" "$tmp/t2/results.csv"
rows=("threads 1|$r1|$w1|1" "threads 2|$r2|$w2|2")
if command -v mpirun > /dev/null; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
  threads=1
  for k in 1 2 3; do
    read -r r _ w < <(run "mpi$k" mpirun -n "$k")
    cmp "$tmp/t2/results.csv" "$tmp/mpi$k/results.csv"
    rows+=("mpi $k ranks|$r|$w|$k")
  done
  echo "results.csv: 1 and 2 threads and 1, 2, 3 MPI ranks byte-identical"
else
  echo "results.csv: 1 and 2 threads byte-identical (no mpirun: MPI not measured)"
fi

/usr/bin/python3 - "$r1" "$n" "${rows[@]}" <<'EOF'
import sys
r1, n, rows = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3:]
print("%-14s %9s %8s %9s %8s %9s" % ("run", "runs", "wall s", "runs/s", "speedup", "per core"))
for row in rows:
    name, r, w, p = row.split("|")
    r, w, p = float(r), float(w), int(p)
    print("%-14s %9d %8.2f %9.1f %8.2f %9.1f" % (name, n, w, r, r / r1, r / p))
s2 = float(rows[1].split("|")[1]) / r1
f = (1 / s2 - 1 / 2) / (1 - 1 / 2)
print("Amdahl from 2 threads: speedup %.2f, serial fraction f = %.3f" % (s2, f))
if f <= 0:
    print("  (f <= 0: no serial part measurable at 2 cores; the predictions below are the ideal n)")
    f = 0.0
print("  predicted speedup: " + ", ".join("%d cores %.1f" % (k, 1 / (f + (1 - f) / k)) for k in (8, 32, 64)))
EOF
