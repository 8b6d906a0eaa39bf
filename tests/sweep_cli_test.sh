#!/usr/bin/env bash
# `vines sweep` from the command line: the same result set from threads and
# from MPI ranks (when the build has MPI), and Ctrl-C keeping finished runs.
# usage: sweep_cli_test.sh VINES_BINARY SOURCE_DIR
set -euo pipefail
vines=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
spec=$src/tests/data/mini_sweep.toml

"$vines" sweep "$spec" --threads 2 --out "$tmp/threads" --no-progress
"$vines" sweep "$spec" --threads 1 --out "$tmp/one" --no-progress
cmp "$tmp/threads/results.csv" "$tmp/one/results.csv"
echo "threads: identical results with 1 and 2 threads"

if [[ "${VINES_TEST_MPI:-0}" == 1 ]]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
  mpirun -n 3 "$vines" sweep "$spec" --threads 1 --out "$tmp/mpi" --no-progress
  cmp "$tmp/threads/results.csv" "$tmp/mpi/results.csv"
  grep -q '"complete": true' "$tmp/mpi/summary.json"
  echo "mpi: 3 ranks give the threaded result set"
fi

# A record folder as a grid key (data/studies/record_folder.toml on a 2 x 2
# grid): the same results.csv from 1 and 2 threads and from 3 MPI ranks.
gm=${VINES_GROUND_MOTIONS:-$src/../shared/data/ground_motions}
if [[ -d $gm ]]; then
  sed -e "s|folder = \"[^\"]*\"|folder = \"$(cd "$gm" && pwd)\"|" -e "s|count = 5|count = 2|" \
      -e "s|scene = \"../|scene = \"$src/data/|" "$src/data/studies/record_folder.toml" > "$tmp/records.toml"
  "$vines" sweep "$tmp/records.toml" --threads 2 --out "$tmp/rec2" --no-progress
  "$vines" sweep "$tmp/records.toml" --threads 1 --out "$tmp/rec1" --no-progress
  cmp "$tmp/rec2/results.csv" "$tmp/rec1/results.csv"
  grep -q '"group_by": "record.path"' "$tmp/rec2/summary.json"
  if [[ "${VINES_TEST_MPI:-0}" == 1 ]]; then
    mpirun -n 3 "$vines" sweep "$tmp/records.toml" --threads 1 --out "$tmp/recmpi" --no-progress
    cmp "$tmp/rec2/results.csv" "$tmp/recmpi/results.csv"
  fi
  echo "record folder: $(($(wc -l < "$tmp/rec2/results.csv") - 1)) runs, the same results.csv on threads and ranks"
else
  echo "record folder: $gm not found, not checked"
fi

# Ctrl-C: a long sweep stopped early exits 130 and keeps what finished. The IC
# spec at contact rtol 1e-12 with the energy ledger: tens of seconds of runs
# (at its own 1e-6 it can finish within the 3 s on an idle machine).
sed -e 's|"loop.contact_rtol" = 1e-6|"loop.contact_rtol" = 1e-12|' -e 's|"loop.energy_ledger" = false|"loop.energy_ledger" = true|' \
    -e "s|scene = \"../|scene = \"$src/data/|" "$src/data/studies/initial_conditions.toml" > "$tmp/ic_slow.toml"
grep -q '"loop.contact_rtol" = 1e-12' "$tmp/ic_slow.toml"
"$vines" sweep "$tmp/ic_slow.toml" --threads 2 --out "$tmp/int" --no-progress &
pid=$!
sleep 3
kill -INT "$pid"
set +e
wait "$pid"
rc=$?
set -e
[[ $rc == 130 ]] || { echo "interrupted sweep exited $rc, not 130"; exit 1; }
grep -q '"complete": false' "$tmp/int/summary.json"
rows=$(($(wc -l < "$tmp/int/results.csv") - 1))
[[ $rows -gt 0 ]] || { echo "no finished run kept"; exit 1; }
echo "interrupt: exit 130, $rows finished runs kept"
