#!/usr/bin/env bash
# The main job: installs what is missing, builds the host program, runs the
# default El Centro scenes of docs/model.md (VI NES and TMD, each with the bare
# frame alongside) and plots them like the paper's Fig. 6-9.
# Results: out/elcentro_vines/, out/elcentro_tmd/ (summary.json,
# timeseries.csv) and out/plots/*.png. Installs only the package set `main`
# (tools/setup.sh: `build` first, then `plots` while the program compiles)
# and builds only the program; tools/test.sh does the rest. Prints how long
# each part took.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

start=$SECONDS
lap() { echo "main.sh: $1 in $((SECONDS - start)) s"; }

bash tools/setup.sh build
lap "build packages ready"
# The plot packages install in the background while the program compiles;
# their log is out/setup_plots.log. Whatever happens next, the script waits
# for that install before it ends (no dpkg left half way).
mkdir -p out
bash tools/setup.sh plots >out/setup_plots.log 2>&1 </dev/null &
plots_pid=$!
trap 'wait "$plots_pid" 2>/dev/null || true' EXIT

# Only what the main job's scenes need: the 10-story frame in double (every
# device), not float nor fixed point, not the 1-story frame of the tests nor
# the extra frames of `vines stress`: 40 % of the build's time and more. A
# scene in another scalar says how to build it; `cmake --preset release`
# (tools/test.sh) brings everything back.
cmake --preset release -DVINES_STORY_COUNTS=10 -DVINES_SCALARS=double -DVINES_STRESS_STORY_COUNTS= >/dev/null
cmake --build --preset release -j2 --target vines
lap "vines built"
for scene in elcentro_vines elcentro_tmd; do
  build/release/vines run "data/scenes/${scene}.toml" --out "out/${scene}"
done
lap "scenes run"

if ! wait "$plots_pid"; then
  echo "main.sh: installing the plot packages failed (tools/setup.sh plots); its log, out/setup_plots.log, ends:" >&2
  tail -n 20 out/setup_plots.log >&2
  exit 1
fi
lap "plot packages ready"
/usr/bin/python3 tools/plot_run.py out/elcentro_vines out/elcentro_tmd --out out/plots
lap "done"
