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

# Ctrl-C: a long sweep stopped early exits 130 and keeps what finished.
"$vines" sweep "$src/data/studies/initial_conditions.toml" --threads 2 --out "$tmp/int" --no-progress &
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
