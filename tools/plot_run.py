#!/usr/bin/python3
"""Plot `vines run` outputs like the paper's Figures 6-9.

Usage: plot_run.py RUN_DIR [RUN_DIR ...] [--out DIR] [--dpi DPI]

Each RUN_DIR holds summary.json and timeseries.csv or timeseries.npy (a bare, TMD or VI NES run).
Writes into --out (default: out/plots; not a run folder, which vines run owns):
  fig6_top_displacement.png  top-floor displacement vs time, bare vs each device
  fig7_particle_walls.png    VI NES particle and box walls vs time, contacts marked
  fig8_elastic_energy.png    cumulative elastic energy, normalised by the bare final value
  fig9_peaks_per_floor.png   peak displacement and peak inter-story drift per floor
The bare reference comes from a run with device "none" if one is given, else from the
bare_* columns and the "bare" block of the first device run.
Exit code 2, with a message naming the path, on a missing directory, file, key or column.
"""
import argparse
import json
import os
import sys

import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 150
KIND = {"none": "w/o device", "tmd": "TMD", "vines": "VI NES"}
COLORS = {"none": ["k"], "tmd": ["tab:blue", "tab:cyan", "tab:purple"],
          "vines": ["tab:red", "tab:orange", "tab:brown", "tab:pink"]}


def fail(msg):
    print(f"plot_run.py: error: {msg}", file=sys.stderr)
    sys.exit(2)


class Run:
    """One run directory: its summary and the columns of its time series."""

    def __init__(self, path):
        self.path = path
        if not os.path.isdir(path):
            fail(f"run directory not found: {path}")
        self.summary_path = os.path.join(path, "summary.json")
        self.csv_path = os.path.join(path, "timeseries.csv")
        npy = os.path.join(path, "timeseries.npy")
        if not os.path.isfile(self.csv_path) and os.path.isfile(npy):
            self.csv_path = npy
        for p in (self.summary_path, self.csv_path):
            if not os.path.isfile(p):
                fail(f"missing file: {p}")
        try:
            with open(self.summary_path) as fh:
                self.summary = json.load(fh)
        except (OSError, ValueError) as e:
            fail(f"cannot read {self.summary_path}: {e}")
        self.device = self.key("device")
        if self.device not in KIND:
            fail(f"{self.summary_path}: unknown device {self.device!r}")
        self.n = int(self.key("stories"))
        self._cols = None
        self.label = KIND[self.device]
        if self.device == "vines" and self.summary.get("contact_law"):
            self.label += f" ({self.summary['contact_law']})"
        self.color = "k"

    def key(self, name, block=None):
        d = self.summary if block is None else self.key(block)
        if not isinstance(d, dict) or name not in d:
            where = name if block is None else f"{block}.{name}"
            fail(f"{self.summary_path}: key '{where}' is absent")
        return d[name]

    def col(self, name):
        """A column of the time series as a float array (file read once, lazily)."""
        if self._cols is None and self.csv_path.endswith(".npy"):
            try:
                data = np.load(self.csv_path)
            except (OSError, ValueError) as e:
                fail(f"cannot read {self.csv_path}: {e}")
            if data.dtype.names is None:
                fail(f"{self.csv_path}: not a table of named columns")
            self._cols = {h: data[h].astype(float) for h in data.dtype.names}
        if self._cols is None:
            try:
                with open(self.csv_path) as fh:
                    header = [h.strip() for h in fh.readline().split(",")]
                try:
                    data = np.loadtxt(self.csv_path, delimiter=",", skiprows=1, ndmin=2)
                except ValueError:  # non-numeric extra columns: read them as NaN
                    data = np.genfromtxt(self.csv_path, delimiter=",", skip_header=1, ndmin=2)
            except (OSError, ValueError) as e:
                fail(f"cannot read {self.csv_path}: {e}")
            if data.shape[1] != len(header):
                fail(f"{self.csv_path}: {len(header)} header names but {data.shape[1]} columns")
            self._cols = {h: data[:, i] for i, h in enumerate(header)}
        if name not in self._cols:
            fail(f"{self.csv_path}: column '{name}' is absent")
        return self._cols[name]


class Bare:
    """The uncontrolled frame: a bare run, or the bare_* data carried by a device run."""

    def __init__(self, runs):
        self.run = next((r for r in runs if r.device == "none"), None)
        self.src = self.run or next((r for r in runs if r.device != "none"), None)

    def t(self):
        return self.src.col("t_s")

    def x_top(self):
        r = self.src
        return r.col(f"x{r.n}_m") if self.run else r.col("bare_x_top_m")

    def ee(self):
        return self.src.col("Ee_Js") if self.run else self.src.col("bare_Ee_Js")

    def peak(self, name):
        return self.src.key(name) if self.run else self.src.key(name, "bare")


def check(runs, bare):
    """Fail early, before writing anything, if a column or key a figure needs is absent."""
    for r in runs:
        for c in ["t_s", f"x{r.n}_m", "Ee_Js"]:
            r.col(c)
        if r.device == "vines":
            for c in ("particle_x_m", "wall_left_m", "wall_right_m", "contact_force_n"):
                r.col(c)
        for k in ("peak_displacement_m", "peak_drift_m"):
            r.key(k)
    bare.t(), bare.x_top(), bare.ee()
    for k in ("peak_displacement_m", "peak_drift_m"):
        bare.peak(k)


def pct(run, name):
    v = run.summary.get(name)
    return f", ${name[0]}_{{r}}$ = {100 * v:.1f} %" if isinstance(v, (int, float)) else ""


def finish(fig, out, name, written):
    fig.tight_layout()
    path = os.path.join(out, name)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    written.append(path)


def fig6(bare, devs, out, written):
    fig, ax = plt.subplots(figsize=(10, 4.5))
    ax.plot(bare.t(), bare.x_top(), color="k", lw=0.9, label=KIND["none"])
    for r in devs:
        ax.plot(r.col("t_s"), r.col(f"x{r.n}_m"), color=r.color, lw=0.9,
                label=r.label + pct(r, "x_r"))
    ax.axhline(0, color="0.5", lw=0.5)
    ax.set(xlabel="time $t$ [s]", ylabel=f"top-floor displacement $x_{{{bare.src.n}}}$ [m]",
           title="Fig. 6: displacement of the top floor (relative to ground)")
    ax.grid(alpha=0.4)
    ax.legend(loc="upper right")
    finish(fig, out, "fig6_top_displacement.png", written)


def contact_onsets(r, f_tol=1.0, d_tol=1e-6):
    """Indices of the first output sample of each contact, and whether it is the right wall.
    A sample is in contact if |contact_force_n| > f_tol [N] or the overlap exceeds d_tol [m]
    (tolerances so that rounding at the start, particle resting on the wall, is not a contact).
    Contacts shorter than the output step may fall between samples and go unmarked."""
    xp, wl, wr = r.col("particle_x_m"), r.col("wall_left_m"), r.col("wall_right_m")
    on = (np.abs(r.col("contact_force_n")) > f_tol) | (xp < wl - d_tol) | (xp > wr + d_tol)
    idx = np.flatnonzero(on & ~np.concatenate(([False], on[:-1])))
    return idx, xp[idx] > 0.5 * (wl[idx] + wr[idx])


def fig7(vines, out, written):
    fig, axes = plt.subplots(len(vines), 1, figsize=(10, 4.5 * len(vines)), squeeze=False)
    for ax, r in zip(axes[:, 0], vines):
        t = r.col("t_s")
        ax.plot(t, r.col("wall_left_m"), color="tab:blue", lw=0.8, label="left wall")
        ax.plot(t, r.col("wall_right_m"), color="tab:green", lw=0.8, label="right wall")
        ax.plot(t, r.col("particle_x_m"), color=r.color, lw=0.9, label="particle centre")
        idx, right = contact_onsets(r)
        for sel, mk, name in ((~right, ">", "left"), (right, "<", "right")):
            ax.plot(t[idx[sel]], r.col("particle_x_m")[idx[sel]], mk, color="k", ms=6,
                    ls="none", label=f"contact onset, {name} wall ({sel.sum()} at output samples)")
        n = r.summary.get("contacts")
        ax.set(xlabel="time $t$ [s]", ylabel="displacement (relative to ground) [m]",
               title=f"Fig. 7: VI NES particle and box walls — {r.label}"
                     + (f", {n} contacts in summary" if n is not None else ""))
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + 0.3 * (hi - lo))  # headroom for the legend
        ax.grid(alpha=0.4)
        ax.legend(loc="upper right", fontsize=8, ncol=2)
    finish(fig, out, "fig7_particle_walls.png", written)


def fig8(bare, devs, out, written):
    ref = bare.ee()[-1]
    if not ref > 0:
        fail(f"bare elastic energy is not positive in {bare.src.csv_path}")
    fig, ax = plt.subplots(figsize=(10, 4.5))
    ax.plot(bare.t(), bare.ee() / ref, color="k", lw=1.2, label=KIND["none"])
    for r in devs:
        ax.plot(r.col("t_s"), r.col("Ee_Js") / ref, color=r.color, lw=1.2,
                label=r.label + pct(r, "E_r"))
    ax.set(xlabel="time $t$ [s]",
           ylabel="$E_e(t)\\,/\\,E_e^{\\mathrm{bare}}(t_{\\mathrm{end}})$ [-]",
           title="Fig. 8: cumulative elastic energy of the frame, $E_e(t)=\\int_0^t(1/2)\\,x^TKx\\,dt$"
                 f"  (bare final value {ref:.4g} J s)")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.4)
    ax.legend(loc="upper left")
    finish(fig, out, "fig8_elastic_energy.png", written)


def fig9(bare, devs, out, written):
    fig, axes = plt.subplots(1, 2, figsize=(10, 5.5), sharey=True)
    panels = (("peak_displacement_m", "(a) peak displacement $\\max|x_i|$ [m]"),
              ("peak_drift_m", "(b) peak inter-story drift $\\max|x_i - x_{i-1}|$ [m]"))
    for ax, (key, xlabel) in zip(axes, panels):
        series = [(bare.peak(key), "k", KIND["none"], "s")]
        series += [(r.key(key), r.color, r.label, "o") for r in devs]
        for vals, color, label, mk in series:
            vals = np.asarray(vals, float)
            ax.plot(vals, np.arange(1, len(vals) + 1), marker=mk, color=color, label=label)
        ax.set_xlabel(xlabel)
        ax.set_xlim(left=0)
        ax.grid(alpha=0.4)
    n = len(bare.peak("peak_displacement_m"))
    axes[0].set_ylabel("floor $i$ (1 = bottom)")
    axes[1].set_ylabel("story $i$ (between floors $i-1$ and $i$)")
    axes[1].tick_params(labelleft=True)
    axes[0].set_yticks(range(1, n + 1))
    axes[0].legend(loc="lower right", fontsize=9)
    fig.suptitle("Fig. 9: peak response per floor")
    finish(fig, out, "fig9_peaks_per_floor.png", written)


def main(argv=None):
    global DPI
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    ap.add_argument("--out", help="output directory (default: out/plots)")
    ap.add_argument("--dpi", type=float, default=DPI, help=f"resolution of the PNGs (default: {DPI})")
    args = ap.parse_args(argv)
    if not args.dpi > 0:
        ap.error(f"--dpi must be positive, not {args.dpi}")
    DPI = args.dpi
    runs = [Run(p) for p in args.run_dirs]
    out = args.out or "out/plots"
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        fail(f"cannot create output directory {out}: {e}")
    devs = [r for r in runs if r.device != "none"]
    for kind in ("tmd", "vines"):
        same = [r for r in devs if r.device == kind]
        labels = [r.label for r in same]
        for i, r in enumerate(same):
            r.color = COLORS[kind][i % len(COLORS[kind])]
            if labels.count(r.label) > 1:  # same kind and law twice: name the directory
                r.label += f" [{os.path.basename(os.path.normpath(r.path))}]"
    bare = Bare(runs)
    check(runs, bare)
    written = []
    fig6(bare, devs, out, written)
    vines = [r for r in devs if r.device == "vines"]
    if vines:
        fig7(vines, out, written)
    else:
        print("fig7_particle_walls.png skipped: no VI NES run given", file=sys.stderr)
    fig8(bare, devs, out, written)
    fig9(bare, devs, out, written)
    for p in written:
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
