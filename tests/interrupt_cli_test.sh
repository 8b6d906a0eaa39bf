#!/usr/bin/env bash
# `vines sweep` stopped and resumed: Ctrl-C answered within a second, every
# finished run in DIR/runs.jsonl as it finishes, a second Ctrl-C or a kill
# losing nothing that finished, --resume completing the sweep into the
# uninterrupted results, a log of another spec refused, huge plans refused at
# once and --large accepted.
# usage: interrupt_cli_test.sh VINES_BINARY SOURCE_DIR
set -euo pipefail
vines=$1
src=$2
tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT

# Runs of about a second each (on an idle core): El Centro at a 100 kHz sensor rate.
spec=$tmp/long.toml
cat > "$spec" <<EOF
[[study]]
name = "long"
scene = "$src/data/scenes/elcentro_vines.toml"
[study.set]
"loop.sensor_rate_hz" = 100000.0
"output.rate_hz" = 50.0
[study.grid]
"vines.beta" = [1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 1.9]
EOF

fail() { echo "FAIL: $*"; exit 1; }
now() { date +%s.%N; }
# Waits until DIR/runs.jsonl holds a finished run (its header and one row).
wait_row() {
  for _ in $(seq 600); do
    [[ -f $1/runs.jsonl && $(wc -l < "$1/runs.jsonl") -ge 2 ]] && return 0
    sleep 0.1
  done
  fail "no finished run in $1/runs.jsonl after 60 s"
}
# Waits for `pid` to exit within `limit` seconds; sets rc and took.
wait_exit() {
  local pid=$1 limit=$2 t0
  t0=$(now)
  while kill -0 "$pid" 2>/dev/null; do
    awk -v a="$t0" -v b="$(now)" -v l="$limit" 'BEGIN { exit !(b - a > l) }' && fail "still running after $limit s"
    sleep 0.02
  done
  set +e
  wait "$pid"
  rc=$?
  set -e
  took=$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')
}
rows() { echo $(($(wc -l < "$1") - 1)); }

# Ctrl-C in the middle of runs of several seconds (300 kHz): they are
# dropped, the sweep exits within a second.
sed 's/100000.0/300000.0/; s/^"vines.beta" = .*/"vines.beta" = [1.3, 1.4]/' "$spec" > "$tmp/longer.toml"
"$vines" sweep "$tmp/longer.toml" --threads 2 --out "$tmp/mid" --no-progress > /dev/null 2>&1 &
pid=$!
sleep 1
kill -INT $pid
wait_exit $pid 1.5
[[ $rc == 130 ]] || fail "sweep stopped mid-run exited $rc, not 130"
echo "Ctrl-C mid-run: exit 130 after $took s"

# The uninterrupted sweep.
"$vines" sweep "$spec" --threads 2 --out "$tmp/full" --no-progress > /dev/null
[[ $(rows "$tmp/full/runs.jsonl") == 8 ]] || fail "the log of a whole sweep lacks runs"

# Ctrl-C once: acknowledged within a second, exit 130 within a second, the
# finished runs in results.csv (partial) and in the log.
"$vines" sweep "$spec" --threads 2 --out "$tmp/int" --no-progress > /dev/null 2> "$tmp/int.err" &
pid=$!
wait_row "$tmp/int"
kill -INT $pid
t0=$(now)
until grep -q "stopping (Ctrl-C)" "$tmp/int.err"; do
  awk -v a="$t0" -v b="$(now)" 'BEGIN { exit !(b - a > 1) }' && fail "Ctrl-C not acknowledged within 1 s"
  sleep 0.02
done
wait_exit $pid 1.5
[[ $rc == 130 ]] || fail "interrupted sweep exited $rc, not 130"
grep -q '"complete": false' "$tmp/int/summary.json" || fail "a stopped sweep's summary is not marked partial"
done_rows=$(rows "$tmp/int/results.csv")
[[ $done_rows -gt 0 && $done_rows -lt 8 && $done_rows == $(rows "$tmp/int/runs.jsonl") ]] ||
  fail "results.csv has $done_rows runs, the log $(rows "$tmp/int/runs.jsonl")"
echo "Ctrl-C: acknowledged, exit 130 after $took s, $done_rows finished runs kept"

# Two quick Ctrl-Cs: exit 130 at once, the finished runs in the log.
"$vines" sweep "$spec" --threads 2 --out "$tmp/twice" --no-progress > /dev/null 2>&1 &
pid=$!
wait_row "$tmp/twice"
kill -INT $pid
kill -INT $pid 2>/dev/null || true  # unless the first already ended it
wait_exit $pid 1
[[ $rc == 130 ]] || fail "twice interrupted sweep exited $rc, not 130"
[[ $(rows "$tmp/twice/runs.jsonl") -ge 1 ]] || fail "two Ctrl-Cs lost the finished runs"
echo "two Ctrl-Cs: exit 130 after $took s, $(rows "$tmp/twice/runs.jsonl") finished runs in the log"

# A kill: the log keeps the finished runs.
"$vines" sweep "$spec" --threads 2 --out "$tmp/kill" --no-progress > /dev/null 2>&1 &
pid=$!
wait_row "$tmp/kill"
kill -KILL $pid
{ wait $pid; } 2>/dev/null || true
echo "kill: $(rows "$tmp/kill/runs.jsonl") finished runs in the log"

# --resume completes each into the uninterrupted results (byte for byte but
# the wall-clock fields).
for d in int twice kill; do
  "$vines" sweep "$spec" --threads 2 --resume "$tmp/$d" --no-progress > /dev/null 2> "$tmp/$d.resume"
  grep -q "resuming" "$tmp/$d.resume" || fail "$d: no resume message"
  cmp "$tmp/full/results.csv" "$tmp/$d/results.csv" || fail "$d: resumed results.csv differs"
  for f in full $d; do grep -v -e wall_time_s -e runs_per_s "$tmp/$f/summary.json" > "$tmp/$f.summary"; done
  cmp "$tmp/full.summary" "$tmp/$d.summary" || fail "$d: resumed summary.json differs"
done
echo "resume: the interrupted, twice interrupted and killed sweeps end as the uninterrupted one"

# A log of another spec is refused.
set +e
"$vines" sweep "$src/tests/data/mini_sweep.toml" --resume "$tmp/full" --no-progress > /dev/null 2> "$tmp/other.err"
rc=$?
set -e
[[ $rc == 1 ]] && grep -q "runs.jsonl: the log is of another spec or plan" "$tmp/other.err" ||
  fail "resume with another spec: exit $rc, $(cat "$tmp/other.err")"
echo "resume of another spec: refused"

# 1e10 runs: refused at once with the size; a plan just above 1e6 runs
# needs --large (its size and time first).
cat > "$tmp/huge.toml" <<EOF
[[study]]
scene = "$src/data/scenes/elcentro_vines.toml"
[study.set]
"loop.sensor_rate_hz" = 50.0
[study.grid]
"vines.beta" = { from = 1.1, to = 2.0, count = 100000 }
"vines.eps" = { from = 0.1, to = 1.0, count = 100000 }
EOF
t0=$(now)
set +e
"$vines" sweep "$tmp/huge.toml" --out "$tmp/huge" --large > /dev/null 2> "$tmp/huge.err"
rc=$?
set -e
refused_in=$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')
[[ $rc == 1 ]] && grep -q "the plan has 10000000000 runs" "$tmp/huge.err" || fail "1e10 runs: exit $rc, $(cat "$tmp/huge.err")"
awk -v t="$refused_in" 'BEGIN { exit !(t < 1) }' || fail "1e10 runs refused after $refused_in s"
[[ ! -e $tmp/huge ]] || fail "a refused plan created its folder"
sed -i 's/count = 100000 }/count = 1001 }/; s/eps" = { from = 0.1, to = 1.0, count = 1001 }/eps" = { from = 0.1, to = 1.0, count = 1000 }/' "$tmp/huge.toml"
set +e
"$vines" sweep "$tmp/huge.toml" --out "$tmp/large" --threads 2 > /dev/null 2> "$tmp/large.err"
rc=$?
set -e
[[ $rc == 1 ]] && grep -q "the plan has 1001000 runs.*about .* on 2 threads: pass --large" "$tmp/large.err" ||
  fail "1001000 runs without --large: exit $rc, $(cat "$tmp/large.err")"
"$vines" sweep "$tmp/huge.toml" --out "$tmp/large" --threads 2 --large --no-progress > /dev/null 2> "$tmp/large.err" &
pid=$!
for _ in $(seq 600); do grep -q -- "(--large)" "$tmp/large.err" && break; sleep 0.1; done
grep -q "vines sweep: 1001000 runs, about" "$tmp/large.err" || fail "--large: no size and time: $(cat "$tmp/large.err")"
wait_row "$tmp/large"
kill -INT $pid
wait_exit $pid 5
[[ $rc == 130 ]] || fail "--large sweep stopped with exit $rc"
echo "plans: 1e10 runs refused in $refused_in s, 1001000 runs need --large and run with it"
