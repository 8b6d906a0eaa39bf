#!/usr/bin/python3
"""Plot `vines bench --csv` output: error of the peak top displacement against
wall time per full run (log-log), one panel per scene, one series per method,
scalar and sensor rate (the points of a series are its tolerances).

Usage: plot_bench.py BENCH.csv [--out FILE.png]
Exit code 2, with a message naming the path, on a missing file or column.
"""
import argparse
from collections import defaultdict

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from figures import fail, read_csv  # noqa: E402

COLUMNS = ["scene", "method", "scalar", "sensor_rate_hz", "contact_rtol", "wall_s_median", "peak_rel_error"]
FLOOR = 1e-16  # errors below this are drawn at it (log scale)


def load(path):
    return read_csv(path, COLUMNS, "plot_bench.py")


def number(v):
    try:
        return float(v)
    except ValueError:
        return float("nan")  # null in the CSV: no truth for that line


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--out", default="work_precision.png")
    a = ap.parse_args()
    rows = load(a.csv)
    if not rows:
        fail("plot_bench.py", f"{a.csv}: no lines")
    # The points of each scene: (method, scalar, rate) -> [(wall, error)]; a line
    # without a truth (null error: no reference for its scene) has none.
    by_scene = defaultdict(lambda: defaultdict(list))
    for r in rows:
        scene = r["scene"].strip('"')
        by_scene[scene]
        err = number(r["peak_rel_error"])
        if err == err:
            key = (r["method"].strip('"'), r["scalar"].strip('"'), number(r["sensor_rate_hz"]))
            by_scene[scene][key].append((number(r["wall_s_median"]), max(err, FLOOR)))
    scenes = sorted(s for s in by_scene if by_scene[s])
    for s in sorted(set(by_scene) - set(scenes)):
        print(f"plot_bench.py: {s}: no line has a reference error (no data/reference file?): not drawn")
    if not scenes:
        fail("plot_bench.py", f"{a.csv}: no line has a reference error")
    cols = min(3, len(scenes))
    nrows = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 4.2 * nrows), squeeze=False)
    for ax, scene in zip(axes.flat, scenes):
        series = by_scene[scene]
        for (method, scalar, rate), pts in sorted(series.items()):
            pts.sort()
            label = f"{method} {scalar}" + (f" {rate:g} Hz" if method == "firmware" else "")
            style = "o-" if method == "firmware" else "s--"
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, ms=4, label=label)
        ax.axhline(1e-6, color="grey", lw=0.8, ls=":")
        ax.set_title(scene)
        ax.set_xlabel("wall time per full run [s]")
        ax.set_ylabel("peak top displacement, relative error")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=6)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(a.out, dpi=130)
    print(f"plot_bench.py: wrote {a.out}")


if __name__ == "__main__":
    main()
