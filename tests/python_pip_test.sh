#!/usr/bin/env bash
# docs/python.md's `pip install .` lines, run as written but for
# the venv's folder (a scratch one) and the build tree (the configured one
# reused through VINES_BUILD_DIR, so the extension is not compiled twice);
# the installed package, imported from outside the checkout, gives the same
# run as the build tree's and is typed (py.typed and the extension's stub). No
# package index is used.
# Usage: python_pip_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$(cd "$1" && pwd)
build_dir=$(cd "$2" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

mapfile -t lines < <(grep -E '^(/usr/bin/python3 -m venv|~/venvs/vines/bin/pip) ' "$source_dir/docs/python.md")
((${#lines[@]} == 2)) || { echo "FAIL: docs/python.md has not its two pip lines" >&2; exit 1; }
for line in "${lines[@]}"; do
  echo "run: $line"
  (cd "$source_dir" && VINES_BUILD_DIR=$build_dir PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 \
    bash -c "${line//\~\/venvs\/vines/$work/venv}") > "$work/log" 2>&1 ||
    { tail -n 30 "$work/log"; echo "FAIL: $line" >&2; exit 1; }
done

scene=$source_dir/data/scenes/elcentro_vines.toml
check='
import os, sys, vines
here = os.path.dirname(vines.__file__)
assert all(os.path.isfile(os.path.join(here, f)) for f in ("py.typed", "_vines.pyi")), "typing files missing"
scene = vines.Scene.load(sys.argv[1])
r = vines.run(scene.with_({"loop.sensor_rate_hz": 50.0, "output.rate_hz": 50.0}))
print(vines.__file__)
print(repr((r.x_r, r.E_r, r.peak_top_displacement_m, r.contacts)))'
installed=$(cd "$work" && "$work/venv/bin/python" -c "$check" "$scene")
built=$(cd "$work" && PYTHONPATH=$build_dir/python /usr/bin/python3 -c "$check" "$scene")
echo "installed: $installed"
echo "built:     $built"
case $(head -n1 <<<"$installed") in
  "$work"/venv/*) ;;
  *) echo "FAIL: the venv imported vines from outside it" >&2; exit 1 ;;
esac
[[ $(tail -n1 <<<"$installed") == "$(tail -n1 <<<"$built")" ]] ||
  { echo "FAIL: the installed package's run differs from the build tree's" >&2; exit 1; }
echo "pip install: ok"
