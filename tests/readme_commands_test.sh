#!/usr/bin/env bash
# Runs every command README.md shows, as written, against the vines under test:
#   tests/readme_commands_test.sh VINES SOURCE_DIR
# The shell blocks (```sh) of README.md are read, continued lines (ending in
# '\') joined, and each line starting with build/release/vines, python3 or
# /usr/bin/python3 tools/... or tools/... is run with bash in a scratch copy of
# the repository (data/ copied, so `vines reference` rewrites the copy;
# build/release/vines -> VINES; ../shared -> the real ground motions; /tmp/ ->
# the scratch folder). A nonzero exit fails the test, naming the line. Lines
# that need what this test cannot give are skipped, each with its reason below.
set -uo pipefail
VINES=$(realpath "$1")
SRC=$(realpath "$2")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

# Why a line is not run ("" = run it).
skip_reason() {
  case "$1" in
    "bash tools/main.sh"* | "bash tools/test.sh"* | "bash tools/bench.sh"*)
      echo "installs packages and builds every preset (the builds are what this test runs on)" ;;
    cmake* | ctest*) echo "a build or the MCU test run: done by the build this test runs in, or by tools/test.sh" ;;
    *"--node qemu:"* | "tools/mcu_report.py"*)
      echo "needs the Cortex-M images and QEMU (built and run by tools/test.sh)" ;;
    mpirun*) command -v mpirun > /dev/null || echo "mpirun not installed" ;;
    *) ;;
  esac
}

# mpirun in a container runs as root and on fewer cores than the README's 4
# ranks: allowed here (as in sweep_cli_test.sh).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

# The scratch repository: its own data/ and out/, the tools and the binary.
REPO=$WORK/repo
mkdir -p "$REPO/build/release" "$WORK/tmp"
cp -r "$SRC/data" "$REPO/data"
ln -s "$SRC/tools" "$REPO/tools"
ln -s "$VINES" "$REPO/build/release/vines"
ln -s "$(realpath "$SRC/../shared")" "$WORK/shared"

# The README's shell lines, continuations joined.
mapfile -t LINES < <(awk '
  /^```/ { if (inb) { inb = 0 } else if ($0 ~ /^```(sh|bash)$/) { inb = 1 }; next }
  !inb { next }
  { line = cur $0; sub(/^[ \t]+/, "", line) }
  /\\$/ { sub(/\\$/, "", line); cur = line " "; next }
  { cur = ""; if (line != "") print line }
' "$SRC/README.md")

ran=0
failed=0
for line in "${LINES[@]}"; do
  case "$line" in
    build/release/vines* | python3\ tools/* | /usr/bin/python3\ tools/* | tools/* | bash\ tools/* | cmake* | ctest* | mpirun*) ;;
    *) continue ;;
  esac
  reason=$(skip_reason "$line")
  if [ -n "$reason" ]; then
    echo "skip: $line  -- $reason"
    continue
  fi
  cmd=${line//\/tmp\//$WORK/tmp/}
  echo "run:  $line"
  ran=$((ran + 1))
  (cd "$REPO" && bash -c "$cmd" > "$WORK/last.log" 2>&1)
  rc=$?
  if [ "$rc" -ne 0 ]; then
    echo "FAIL (exit status $rc): $line"
    tail -n 20 "$WORK/last.log"
    failed=$((failed + 1))
  fi
done

echo "readme_commands: $ran run, $failed failed"
[ "$ran" -gt 0 ] && [ "$failed" -eq 0 ]
