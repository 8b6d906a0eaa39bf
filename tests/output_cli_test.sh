#!/usr/bin/env bash
# The commands' writes (sim_host/io/output.hpp) from the command line: a write
# that fails (file-size limit: EFBIG, as a full disk) exits nonzero naming the
# file and the reason, leaves no partial or temporary file and keeps the
# previous results; a run owns its folder (stale files removed, foreign files
# refused); --out "" is a usage error; a scene name cannot leave out/.
# usage: output_cli_test.sh VINES_BINARY SOURCE_DIR
set -euo pipefail
vines=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "output_cli: $*" >&2; exit 1; }

# A short El Centro scene (2 s), and the same without timeseries.csv.
sed -e 's/^units = "g"$/units = "g"\nduration_s = 2.0/' "$src/data/scenes/elcentro_vines.toml" > "$tmp/short.toml"
{ cat "$tmp/short.toml"; echo "timeseries = false"; } > "$tmp/noseries.toml"  # [output] is the last table

# Runs "$@" with files limited to 1 KiB (SIGXFSZ ignored: the write sees EFBIG);
# expects a nonzero exit and "FILE: cannot write: File too large" on stderr.
expect_efbig() {
  local file=$1; shift
  set +e
  (trap '' XFSZ; ulimit -f 1; "$@" > /dev/null 2> "$tmp/err.txt")
  local rc=$?
  set -e
  [[ $rc != 0 ]] || fail "$* exited 0 with a file-size limit"
  grep -qF "$file: cannot write: File too large" "$tmp/err.txt" || fail "$*: no message naming $file: $(cat "$tmp/err.txt")"
}
# No temporary file left in folder $1.
no_temp() { [[ -z $(find "$1" -name '.*.tmp-*') ]] || fail "temporary files left in $1: $(ls -A "$1")"; }

# vines run: the earlier results stay whole.
"$vines" run "$tmp/short.toml" --out "$tmp/run" --quiet
cp -r "$tmp/run" "$tmp/run.before"
expect_efbig "$tmp/run/timeseries.csv" "$vines" run "$tmp/short.toml" --out "$tmp/run" --quiet
diff -r -x .vines-output "$tmp/run.before" "$tmp/run" > /dev/null || fail "vines run: earlier results changed by a failed run"
no_temp "$tmp/run"
echo "run: write failure reported, earlier results intact"

# The same with SIGXFSZ at its default (which kills the process): vines
# ignores it, so the limit is a write error with its message and exit 1.
set +e
(ulimit -f 1; "$vines" run "$tmp/short.toml" --out "$tmp/xfsz" --quiet > /dev/null 2> "$tmp/err.txt")
rc=$?
set -e
[[ $rc == 1 ]] || fail "a file-size limit with SIGXFSZ at its default: exit $rc, not 1"
grep -qF "timeseries.csv: cannot write: File too large" "$tmp/err.txt" || fail "no message: $(cat "$tmp/err.txt")"
no_temp "$tmp/xfsz"
echo "run: SIGXFSZ is a write error, not a silent death"

# A run without timeseries.csv removes the earlier one; a foreign file refuses the folder.
"$vines" run "$tmp/noseries.toml" --out "$tmp/run" --quiet
[[ -f $tmp/run/summary.json && ! -e $tmp/run/timeseries.csv ]] || fail "stale timeseries.csv kept: $(ls "$tmp/run")"
touch "$tmp/run/notes.txt"
set +e
"$vines" run "$tmp/short.toml" --out "$tmp/run" --quiet 2> "$tmp/err.txt"
rc=$?
set -e
[[ $rc == 1 ]] || fail "a folder with notes.txt: exit $rc, not 1"
grep -q "notes.txt" "$tmp/err.txt" || fail "the refusal does not name notes.txt: $(cat "$tmp/err.txt")"
[[ -f $tmp/run/notes.txt ]] || fail "notes.txt removed"
echo "run: stale timeseries.csv removed, a folder with a foreign file refused"

# vines sweep: its log of finished runs (runs.jsonl, the new sweep's own) fails
# first; the earlier results.csv and summary.json stay whole.
spec=$src/tests/data/mini_sweep.toml
"$vines" sweep "$spec" --threads 2 --out "$tmp/sweep" --no-progress > /dev/null
cp -r "$tmp/sweep" "$tmp/sweep.before"
expect_efbig "$tmp/sweep/runs.jsonl" "$vines" sweep "$spec" --threads 2 --out "$tmp/sweep" --no-progress
for f in results.csv summary.json; do
  cmp -s "$tmp/sweep.before/$f" "$tmp/sweep/$f" || fail "vines sweep: earlier $f changed by a failed sweep"
done
no_temp "$tmp/sweep"
echo "sweep: write failure reported, earlier results intact"

# vines hil --csv: the same.
hil=("$vines" hil "$tmp/short.toml" --duration 1 --csv "$tmp/hil.csv")
"${hil[@]}" > /dev/null
cp "$tmp/hil.csv" "$tmp/hil.before.csv"
expect_efbig "$tmp/hil.csv" "${hil[@]}"
cmp -s "$tmp/hil.before.csv" "$tmp/hil.csv" || fail "vines hil: earlier hil.csv changed by a failed write"
no_temp "$tmp"
echo "hil --csv: write failure reported, earlier file intact"

# --out "": a usage error naming the option, nothing written.
for cmd in "run $tmp/short.toml" "sweep $spec"; do
  set +e
  # shellcheck disable=SC2086
  (cd "$tmp" && "$vines" $cmd --out "" 2> "$tmp/err.txt")
  rc=$?
  set -e
  [[ $rc == 2 ]] || fail "vines $cmd --out \"\": exit $rc, not 2"
  grep -q -- "--out" "$tmp/err.txt" || fail "vines $cmd --out \"\": message does not name --out"
done
echo "--out \"\": usage error"

# A scene named ../../evil writes into out/, never beside it.
mkdir -p "$tmp/w/c"
sed 's/^name = .*/name = "..\/..\/evil"/' "$tmp/noseries.toml" > "$tmp/w/c/evil.toml"
(cd "$tmp/w/c" && "$vines" run evil.toml --quiet)
[[ -f $tmp/w/c/out/___.._evil/summary.json ]] || fail "no out/___.._evil/summary.json: $(find "$tmp/w")"
[[ ! -e $tmp/evil && ! -e $tmp/w/evil ]] || fail "a scene name wrote outside out/"
echo "name ../../evil: written to out/___.._evil/"
# Refused with exit 1 and TEXT in the message: refused TEXT COMMAND...
refused() {
  local text=$1; shift
  set +e
  "$@" > /dev/null 2> "$tmp/err.txt"
  local rc=$?
  set -e
  [[ $rc == 1 ]] || fail "$*: exit $rc, not 1"
  grep -qF -- "$text" "$tmp/err.txt" || fail "$*: the refusal does not say \"$text\": $(cat "$tmp/err.txt")"
}

# No write through a link: a link (or a hard link) named like an output in a
# vines folder refuses the folder, and the file it leads to is untouched.
echo secret > "$tmp/victim.txt"
"$vines" run "$tmp/noseries.toml" --out "$tmp/linked" --quiet
ln -s "$tmp/victim.txt" "$tmp/linked/timeseries.csv"
refused "timeseries.csv (a link)" "$vines" run "$tmp/short.toml" --out "$tmp/linked" --quiet
rm "$tmp/linked/timeseries.csv" "$tmp/linked/summary.json"
ln "$tmp/victim.txt" "$tmp/linked/summary.json"
refused "summary.json (a hard link)" "$vines" run "$tmp/noseries.toml" --out "$tmp/linked" --quiet
[[ $(cat "$tmp/victim.txt") == secret ]] || fail "a file behind a link was written"
ln -s "$tmp/victim.txt" "$tmp/hil_link.csv"
refused "$tmp/hil_link.csv: cannot write: a symbolic link" "$vines" hil "$tmp/short.toml" --duration 0.2 \
  --csv "$tmp/hil_link.csv"
[[ $(cat "$tmp/victim.txt") == secret ]] || fail "vines hil --csv wrote through a link"
echo "links: refused, the files behind them untouched"

# Ownership by the marker: someone else's summary.json, results.csv or
# runs.jsonl in a folder without it is not vines'; nor is a sweep's folder a run's.
mkdir "$tmp/theirs"
echo '{"mine": true}' > "$tmp/theirs/summary.json"
refused "no .vines-output marker" "$vines" run "$tmp/noseries.toml" --out "$tmp/theirs" --quiet
refused "no .vines-output marker" "$vines" sweep "$spec" --out "$tmp/theirs" --no-progress
[[ $(cat "$tmp/theirs/summary.json") == '{"mine": true}' ]] || fail "someone else's summary.json overwritten"
refused "vines sweep's folder, not vines run's" "$vines" run "$tmp/noseries.toml" --out "$tmp/sweep" --quiet
echo "ownership: a folder without vines' marker, or another command's, refused"

# One command at a time: a sweep under way holds its folder; a second one is
# refused, naming the first; after it, the folder is free.
sed -e 's|"loop.contact_rtol" = 1e-6|"loop.contact_rtol" = 1e-12|' -e "s|scene = \"../|scene = \"$src/data/|" \
  "$src/data/studies/initial_conditions.toml" > "$tmp/slow.toml"
"$vines" sweep "$tmp/slow.toml" --threads 1 --out "$tmp/busy" --no-progress > /dev/null 2>&1 &
first=$!
for _ in $(seq 100); do grep -q '"pid"' "$tmp/busy/.vines-output" 2> /dev/null && break; sleep 0.05; done
refused "in use by vines sweep (process $first)" "$vines" sweep "$spec" --out "$tmp/busy" --no-progress
kill -INT "$first"
wait "$first" || true
"$vines" sweep "$spec" --out "$tmp/busy" --no-progress > /dev/null 2>&1 || fail "the folder stayed locked"
echo "lock: a second sweep on a busy folder refused, naming the first"
echo "output_cli: ok"
