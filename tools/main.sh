#!/usr/bin/env bash
# The main job: installs what is missing, builds the host program, runs the
# default El Centro scenes of docs/model.md (VI NES and TMD, each with the bare
# frame alongside) and plots them like the paper's Fig. 6-9.
# Results: out/elcentro_vines/, out/elcentro_tmd/ (summary.json,
# timeseries.csv) and out/plots/*.png.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j2
for scene in elcentro_vines elcentro_tmd; do
  build/release/vines run "data/scenes/${scene}.toml" --out "out/${scene}"
done
/usr/bin/python3 tools/plot_run.py out/elcentro_vines out/elcentro_tmd --out out/plots
