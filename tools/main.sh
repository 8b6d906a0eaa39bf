#!/usr/bin/env bash
# The main job: installs what is missing, builds the host program, runs the
# default El Centro scenes of docs/model.md (VI NES and TMD, each with the bare
# frame alongside) and plots them like the paper's Fig. 6-9.
# Results: out/elcentro_vines/, out/elcentro_tmd/ (summary.json,
# timeseries.csv) and out/plots/*.png. Installs only the package set `main`
# (tools/setup.sh) and builds only the program; tools/test.sh does the rest.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/setup.sh main
# Only the 10-story frame (every device, double and float: every scene in
# data/ and every README command), not the 1-story frame of the tests nor the
# extra frames of `vines stress`: half the build's time and more.
# `cmake --preset release` (tools/test.sh) brings them back.
cmake --preset release -DVINES_STORY_COUNTS=10 -DVINES_STRESS_STORY_COUNTS= >/dev/null
cmake --build --preset release -j2 --target vines
for scene in elcentro_vines elcentro_tmd; do
  build/release/vines run "data/scenes/${scene}.toml" --out "out/${scene}"
done
/usr/bin/python3 tools/plot_run.py out/elcentro_vines out/elcentro_tmd --out out/plots
