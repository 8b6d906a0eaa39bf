#!/usr/bin/env bash
# Bad inputs on the command line: each is refused at once (exit 1, or 2 for a
# bad option value) with a message naming the input and why, never a hang:
#   tests/input_cli_test.sh VINES SOURCE_DIR
set -uo pipefail
VINES=$(realpath "$1")
SRC=$(realpath "$2")
GM=$(realpath "$SRC/../shared/data/ground_motions")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$SRC"
failed=0

# expect STATUS TEXT -- COMMAND...: the exit status, and TEXT in its stderr
# (10 s at most: a hang fails).
expect() {
  local want=$1 text=$2
  shift 3
  timeout 10 "$@" > "$WORK/out" 2> "$WORK/err" < /dev/null
  local rc=$?
  if [ "$rc" -ne "$want" ] || { [ -n "$text" ] && ! grep -qF -- "$text" "$WORK/err"; }; then
    echo "FAIL: $* -> exit $rc (want $want), stderr:"
    cat "$WORK/err"
    echo "  (wanted: $text)"
    failed=$((failed + 1))
  else
    echo "ok:   $* -> $rc: $(head -n 1 "$WORK/err" | head -c 200)"
  fi
}

# Scene files that are not files.
expect 1 "/dev/zero: not a regular file" -- "$VINES" run /dev/zero
expect 1 "data/scenes: is a directory" -- "$VINES" run data/scenes
echo '[record]' | timeout 10 "$VINES" run /dev/stdin > /dev/null 2> "$WORK/err"
if [ $? -ne 1 ] || ! grep -qF "/dev/stdin: not a regular file" "$WORK/err"; then
  echo "FAIL: a pipe as the scene file"; cat "$WORK/err"; failed=$((failed + 1))
fi
expect 1 "/dev/zero: not a regular file" -- "$VINES" sweep /dev/zero --out "$WORK/s"

# A scene whose record is a device, a record given as a device or folder.
sed 's|^path = .*|path = "/dev/zero"|' data/scenes/elcentro_tmd.toml > "$WORK/dev_record.toml"
expect 1 "record.path: \"/dev/zero\": /dev/zero (absolute) is not a regular file" -- "$VINES" run "$WORK/dev_record.toml"
expect 1 "/dev/zero: not a regular file" -- "$VINES" run data/scenes/elcentro_tmd.toml --record /dev/zero
expect 1 "$GM: is a directory" -- "$VINES" run data/scenes/elcentro_tmd.toml --record "$GM"

# --record: values only need a dt; a forced format is used; a bad one is a usage error.
awk 'NR <= 200 { print $2 }' "$GM/elcentro_1940_ns_2688pts_dt002_time_g.dat" > "$WORK/values.txt"
expect 1 "one column of values and no time: give its sample step with --record-dt" -- \
  "$VINES" run data/scenes/elcentro_tmd.toml --record "$WORK/values.txt" --out "$WORK/v"
expect 0 "" -- "$VINES" run data/scenes/elcentro_tmd.toml --record "$WORK/values.txt" --record-dt 0.02 \
  --out "$WORK/v" --quiet
expect 1 "no 'NPTS= .., DT= ..' header line" -- \
  "$VINES" run data/scenes/elcentro_tmd.toml --record "$WORK/values.txt" --record-format at2 --out "$WORK/v"
expect 2 "--record-format" -- "$VINES" run data/scenes/elcentro_tmd.toml --record "$WORK/values.txt" \
  --record-format nope
expect 2 "--record-dt" -- "$VINES" run data/scenes/elcentro_tmd.toml --record "$WORK/values.txt" --record-dt 5

# Scenes no run can keep: refused at load, naming the keys.
sed -e '/^mass_ratio/d' -e 's|^\[vines\]|[vines]\nradius_m = 1e-6|' data/scenes/elcentro_vines.toml > "$WORK/tiny.toml"
expect 1 "vines.radius_m: the Hertz contact lasts" -- "$VINES" run "$WORK/tiny.toml" --out "$WORK/t"
sed 's|^\[vines\]|[vines]\nyoung_pa = 1|' data/scenes/elcentro_vines.toml > "$WORK/soft.toml"
expect 1 "vines.young_pa: the Hertz overlap" -- "$VINES" run "$WORK/soft.toml" --out "$WORK/t"

# In a sweep, a refused run is a row whose error names the key.
sed '/^mass_ratio/d' data/scenes/elcentro_vines.toml > "$WORK/by_radius.toml"
cat > "$WORK/study.toml" << EOF
[[study]]
name = "radius"
scene = "by_radius.toml"
[study.set]
"loop.sensor_rate_hz" = 50.0
"output.rate_hz" = 50.0
"record.duration_s" = 1.0
[study.grid]
"vines.radius_m" = [1e-6, 1.0]
EOF
timeout 60 "$VINES" sweep "$WORK/study.toml" --out "$WORK/sweep" --no-progress > /dev/null 2>&1
if ! grep -q 'vines.radius_m: the Hertz contact lasts' "$WORK/sweep/results.csv"; then
  echo "FAIL: the refused sweep run's error is not in results.csv:"; cat "$WORK/sweep/results.csv"
  failed=$((failed + 1))
fi

# Options that do not apply are usage errors, not ignored.
KOBE="$GM/kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2"
expect 2 "--record-dt: $KOBE is read as at2" -- "$VINES" run data/scenes/elcentro_vines.toml --record "$KOBE" --record-dt 0.01
expect 2 "--record-units: $KOBE is read as at2" -- "$VINES" run data/scenes/elcentro_vines.toml --record "$KOBE" --record-units m/s2
expect 2 "--record-column: $KOBE is read as at2" -- "$VINES" run data/scenes/elcentro_vines.toml --record "$KOBE" --record-column 2
expect 2 "--image: a board image: it needs --node qemu:TARGET" -- "$VINES" hil data/scenes/elcentro_vines.toml --image x.elf
expect 2 "--comp: a hybrid option: it needs --mode hybrid" -- "$VINES" hil data/scenes/elcentro_vines.toml --mode twin --comp poly
expect 2 "--twin-kappa: a twin option: it needs --mode twin" -- "$VINES" hil data/scenes/elcentro_vines.toml --twin-kappa 3

# A board image that is not one is named, not left to QEMU's register dump.
echo "not an image" > "$WORK/bad.elf"
expect 1 "--image $WORK/bad.elf: not a board image" -- "$VINES" hil data/scenes/elcentro_vines.toml --node qemu:cortex-m7 --image "$WORK/bad.elf"

# A law whose board image was not built: the message says how to build it
# (skipped where someone built it).
if [ ! -e build/cortex-m7/firmware/app/vines_node_restitution.elf ]; then
  expect 1 "-DVINES_NODE_LAWS=restitution && cmake --build --preset cortex-m7" -- \
    "$VINES" hil data/scenes/elcentro_vines_restitution.toml --node qemu:cortex-m7
fi

# A file's bytes in a message are escaped and cut: an escape sequence does
# not reach the terminal raw, a 1 MB token is not printed whole.
printf '0 1\n0.01 \033[31mred\033[0m\n' > "$WORK/esc.txt"
expect 1 'non-numeric token' -- "$VINES" run data/scenes/elcentro_vines.toml --record "$WORK/esc.txt"
if grep -q $'\033' "$WORK/err" || ! grep -qF '\x1b[31mred' "$WORK/err"; then
  echo "FAIL: an escape sequence from a record reached the terminal raw:"; cat -v "$WORK/err"; failed=$((failed + 1))
fi
{ printf '0 1\n0.01 '; head -c 1000000 /dev/zero | tr '\0' 'x'; printf '\n'; } > "$WORK/long.txt"
expect 1 'more bytes)' -- "$VINES" run data/scenes/elcentro_vines.toml --record "$WORK/long.txt"
if [ "$(wc -c < "$WORK/err")" -gt 2000 ]; then
  echo "FAIL: a 1 MB token printed whole ($(wc -c < "$WORK/err") bytes)"; failed=$((failed + 1))
fi
# The monitoring page (in a build with it): a bad address is a usage error,
# a port in use, a host not this machine's, a missing run or a file that is
# not a hil --csv are refused, each named.
if "$VINES" help view > /dev/null 2>&1; then
  expect 2 "--serve 80x: '80x' is not a port" -- "$VINES" hil data/scenes/elcentro_vines.toml --serve 80x
  expect 2 "--serve 70000" -- "$VINES" view "$WORK" --serve 70000
  expect 2 "--serve :80: no host" -- "$VINES" hil data/scenes/elcentro_vines.toml --serve :80
  expect 2 "--serve ::1:0: an IPv6 address goes in brackets" -- "$VINES" hil data/scenes/elcentro_vines.toml --serve ::1:0
  expect 2 "--serve-hold: it needs --serve" -- "$VINES" hil data/scenes/elcentro_vines.toml --serve-hold 5
  expect 2 "--serve-hold" -- "$VINES" hil data/scenes/elcentro_vines.toml --serve 0 --serve-hold -1
  expect 1 "--serve 203.0.113.7:0: cannot listen there" -- "$VINES" hil data/scenes/elcentro_vines.toml \
    --serve 203.0.113.7:0
  expect 1 "$WORK/none.csv: no such file or folder" -- "$VINES" view "$WORK/none.csv"
  expect 1 "not a \`vines hil --csv\` file (no column k)" -- "$VINES" view "$WORK/values.txt"
  printf 'k,t_s,received,ag_sent_mps2,x_top_m\n0,0,1,0,0\n1,0.001,1,0,0\n' > "$WORK/run.csv"
  "$VINES" view "$WORK/run.csv" --serve 0 --for 5 2> "$WORK/view_err" &
  for _ in $(seq 50); do grep -q "page is at" "$WORK/view_err" && break; sleep 0.1; done
  port=$(grep -o '127.0.0.1:[0-9]*' "$WORK/view_err" | cut -d: -f2)
  expect 1 "--serve 127.0.0.1:$port: cannot listen there (Address already in use" -- \
    "$VINES" view "$WORK/run.csv" --serve "$port"
  wait
fi

# A file-size limit with SIGXFSZ at its default: a write error, exit 1.
(ulimit -f 1; expect 1 "cannot write: File too large" -- "$VINES" run data/scenes/elcentro_vines.toml \
  --out "$WORK/xf"; exit "$failed") || failed=$((failed + 1))

echo "input_cli: $failed failed"
[ "$failed" -eq 0 ]
