#!/usr/bin/env bash
# Runs every command the documents show, as written, against the vines under test:
#   tests/readme_commands_test.sh VINES SOURCE_DIR
# The documents are README.md, then docs/*.md in name order (the guides the
# README links to). Their shell blocks (```sh) are read, continued lines (ending
# in '\') joined, and each line starting with build/release/vines, python3 or
# /usr/bin/python3 tools/... or tools/... is run with bash. Each document runs in
# its own scratch copy of the repository, as `bash tools/main.sh` leaves one
# (an out/ folder; data/ copied, so `vines reference` rewrites the copy;
# build/release/vines -> VINES; ../shared -> the real ground motions; /tmp/ ->
# the scratch folder), so a guide read on its own works after the README's two
# commands. A nonzero exit fails the test, naming the document and the line
# where the command starts. Lines that need what this test cannot give are
# skipped, each with its reason below.
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

# mpirun in a container runs as root and on fewer cores than the documents' 4
# ranks: allowed here (as in sweep_cli_test.sh).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

# A scratch repository in $1 ($1/repo, $1/tmp, $1/shared): its own data/ and
# out/, the tools and the binary.
scratch() {
  mkdir -p "$1/repo/build/release" "$1/repo/out" "$1/tmp"
  cp -r "$SRC/data" "$1/repo/data"
  ln -s "$SRC/tools" "$1/repo/tools"
  ln -s "$VINES" "$1/repo/build/release/vines"
  ln -s "$(realpath "$SRC/../shared")" "$1/shared"
}

# The documents, README.md first.
DOCS=(README.md)
for doc in "$SRC"/docs/*.md; do
  [ -e "$doc" ] && DOCS+=("docs/${doc##*/}")
done

ran=0
failed=0
n=0
summary=()
for doc in "${DOCS[@]}"; do
  # The document's shell lines, continuations joined, as "LINE<tab>command"
  # (LINE: where the command starts).
  mapfile -t LINES < <(awk '
    /^```/ { if (inb) { inb = 0 } else if ($0 ~ /^```(sh|bash)$/) { inb = 1 }; next }
    !inb { next }
    { if (cur == "") start = FNR; line = cur $0; sub(/^[ \t]+/, "", line) }
    /\\$/ { sub(/\\$/, "", line); cur = line " "; next }
    { cur = ""; if (line != "") print start "\t" line }
  ' "$SRC/$doc")
  n=$((n + 1))
  DIR=$WORK/$n
  doc_ran=0
  doc_skipped=0
  for entry in "${LINES[@]}"; do
    where=$doc:${entry%%$'\t'*}
    line=${entry#*$'\t'}
    case "$line" in
      build/release/vines* | python3\ tools/* | /usr/bin/python3\ tools/* | tools/* | bash\ tools/* | cmake* | ctest* | mpirun*) ;;
      *) continue ;;
    esac
    reason=$(skip_reason "$line")
    if [ -n "$reason" ]; then
      echo "skip: $where: $line  -- $reason"
      doc_skipped=$((doc_skipped + 1))
      continue
    fi
    [ -d "$DIR" ] || scratch "$DIR"
    cmd=${line//\/tmp\//$DIR/tmp/}
    echo "run:  $where: $line"
    ran=$((ran + 1))
    doc_ran=$((doc_ran + 1))
    (cd "$DIR/repo" && bash -c "$cmd" > "$WORK/last.log" 2>&1)
    rc=$?
    if [ "$rc" -ne 0 ]; then
      echo "FAIL (exit status $rc): $where: $line"
      tail -n 20 "$WORK/last.log"
      failed=$((failed + 1))
    fi
  done
  summary+=("readme_commands: $doc: $doc_ran run, $doc_skipped skipped")
done

printf '%s\n' "${summary[@]}"
echo "readme_commands: $ran run, $failed failed"
[ "$ran" -gt 0 ] && [ "$failed" -eq 0 ]
