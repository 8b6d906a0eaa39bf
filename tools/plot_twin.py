#!/usr/bin/python3
"""Plot a digital-twin run: the estimator's output held against the measured building.

Usage: plot_twin.py TWIN.csv [--out FILE.png] [--truth-scales S1,S2,...] [--title TEXT]

TWIN.csv is the per-step CSV of `vines hil SCENE --mode twin --csv FILE`. Writes one PNG
(default: TWIN.csv with .png instead of .csv) of up to 3 panels sharing the time axis:
  1. roof displacement, estimate vs truth [mm], and their difference;
  2. each story's stiffness factor eta_j (1 = intact) with a band eta +- 2 sd, the truth's
     factors (--truth-scales) dashed, and the first time the damage flag is set;
  3. device force, estimate vs truth [kN], or the TMD's frequency factor sqrt(eta_tmd)
     when the estimator has one (skipped if both forces are all zero).
Rows without telemetry (received = 0) carry no estimate and are left out. A CSV from
`--estimator none` has no eta_* columns: only the roof panel is drawn.
Exit code 2, with a message naming the file or column, on a missing or malformed CSV,
a missing column or an unwritable output.
"""
import argparse
import csv
import os
import re
import sys

import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 150
DAMAGE, DETUNED = 256, 512  # flag bits: damage detected (latched), TMD detuned


def fail(msg):
    print(f"plot_twin.py: error: {msg}", file=sys.stderr)
    sys.exit(2)


def read_csv(path, required):
    """The CSV's columns as float arrays, by header name; fails if one of required is absent."""
    try:
        with open(path, newline="") as fh:
            rows = [r for r in csv.reader(fh) if r]
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        fail(f"cannot read {path}: {e}")
    if not rows:
        fail(f"{path}: empty file")
    header = [h.strip() for h in rows[0]]
    for name in required:
        if name not in header:
            fail(f"{path}: column '{name}' is absent (not a twin CSV?)")
    if len(rows) < 2:
        fail(f"{path}: no data rows after the header")
    data = np.empty((len(rows) - 1, len(header)))
    for i, row in enumerate(rows[1:]):
        if len(row) != len(header):
            fail(f"{path}, line {i + 2}: {len(row)} values but {len(header)} header names")
        for j, v in enumerate(row):
            try:
                data[i, j] = float(v)
            except ValueError:
                fail(f"{path}, line {i + 2}, column '{header[j]}': not a number: {v!r}")
    return {h: data[:, j] for j, h in enumerate(header)}


def first(mask):
    """Index of the first True in mask, or None."""
    idx = np.flatnonzero(mask)
    return idx[0] if idx.size else None


def roof_panel(ax, t, c, got):
    est = np.where(got, c["x_top_m"], np.nan) * 1e3
    truth = c["x_top_truth_m"] * 1e3
    err = est - truth
    rms = np.sqrt(np.nanmean(err ** 2)) if got.any() else np.nan
    ax.plot(t, truth, color="k", lw=1.0, label="truth")
    ax.plot(t, est, color="tab:red", lw=0.9, ls="--", label="estimate")
    ax.plot(t, err, color="tab:blue", lw=0.5, label=f"error (estimate - truth), RMS {rms:.3g} mm")
    ax.axhline(0, color="0.5", lw=0.5)
    ax.set_ylabel("roof displacement [mm]")
    ax.legend(loc="upper right", fontsize=8)


def eta_panel(ax, t, c, got, stories, truth_scales):
    colors = plt.get_cmap("tab10" if len(stories) <= 10 else "tab20").colors
    for n, j in enumerate(stories):
        col = colors[n % len(colors)]
        eta = np.where(got, c[f"eta_{j}"], np.nan)
        sd = c.get(f"eta_sd_{j}", np.zeros_like(eta))
        ax.plot(t, eta, color=col, lw=0.9, label=f"story {j}")
        ax.fill_between(t, eta - 2 * sd, eta + 2 * sd, where=got & (sd > 0), color=col,
                        alpha=0.15, lw=0)
        if truth_scales is not None:
            ax.axhline(truth_scales[n], color=col, lw=0.9, ls="--")
    # y range from the factors, not the bands (the prior's sd is wide), legend headroom on top
    vals = np.concatenate([c[f"eta_{j}"][got] for j in stories] + [truth_scales or []])
    vals = vals[np.isfinite(vals)]
    lo, hi = (vals.min(), vals.max()) if vals.size else (0.0, 1.0)
    pad = max(0.03, 0.5 * (hi - lo))
    ax.set_ylim(lo - pad, hi + pad + 0.4 * (hi - lo + 2 * pad))
    flags = c.get("flags", np.zeros_like(t)).astype(np.int64)
    k = first(got & (flags & DAMAGE > 0))
    if k is None:
        ax.text(0.01, 0.04, "no alarm", transform=ax.transAxes, fontsize=9)
    else:
        story = int(c.get("alarm_story", np.zeros_like(t))[k])
        ax.axvline(t[k], color="k", lw=1.0, ls=":")
        ax.text(t[k], 0.04, f" alarm: story {story} ({t[k]:.2f} s)",
                transform=ax.get_xaxis_transform(), fontsize=9)
    title = "stiffness factors, band $\\pm 2$ sd"
    ax.set_title(title + (", truth dashed" if truth_scales is not None else ""), fontsize=9)
    ax.set_ylabel("stiffness factor $\\eta_j$ [-]")
    ax.legend(loc="upper right", fontsize=7, ncol=min(len(stories), 5))


def device_panel(ax, t, c, got):
    if "eta_tmd" in c:
        eta = np.where(got, c["eta_tmd"], np.nan)
        sd = c.get("eta_sd_tmd", np.zeros_like(eta))
        ax.plot(t, np.sqrt(eta), color="tab:purple", lw=0.9, label="TMD frequency factor")
        ax.fill_between(t, np.sqrt(np.clip(eta - 2 * sd, 0, None)), np.sqrt(eta + 2 * sd),
                        where=got & (sd > 0), color="tab:purple", alpha=0.15, lw=0)
        k = first(got & (c.get("flags", np.zeros_like(t)).astype(np.int64) & DETUNED > 0))
        if k is not None:
            ax.axvline(t[k], color="k", lw=1.0, ls=":", label=f"TMD detuned ({t[k]:.2f} s)")
        ax.set_ylabel("$\\sqrt{\\eta_{tmd}}$ [-]")
    else:
        zero = np.zeros_like(t)
        ax.plot(t, c.get("device_force_truth_n", zero) / 1e3, color="k", lw=0.8, label="truth")
        est = np.where(got, c.get("contact_force_n", zero), np.nan)
        ax.plot(t, est / 1e3, color="tab:red", lw=0.7, ls="--", label="estimate")
        ax.set_ylabel("device force [kN]")
    ax.legend(loc="upper right", fontsize=8)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", metavar="TWIN.csv")
    ap.add_argument("--out", help="output PNG (default: TWIN.csv with .png)")
    ap.add_argument("--truth-scales", help="the truth's per-story factors, comma-separated")
    ap.add_argument("--title", help="figure title (default: the CSV's name)")
    args = ap.parse_args(argv)
    out = args.out or os.path.splitext(args.csv)[0] + ".png"
    if os.path.abspath(out) == os.path.abspath(args.csv):
        fail(f"output {out} would overwrite the input")
    if not os.path.isfile(args.csv):
        fail(f"file not found: {args.csv}")
    if not os.path.isdir(os.path.dirname(out) or "."):
        fail(f"cannot write {out}: no directory {os.path.dirname(out)}")
    c = read_csv(args.csv, ("t_s", "x_top_m", "x_top_truth_m"))
    t = c["t_s"]
    got = c["received"] != 0 if "received" in c else np.ones(t.size, bool)
    stories = sorted(int(m.group(1)) for h in c if (m := re.fullmatch(r"eta_(\d+)", h)))
    truth = None
    if args.truth_scales:
        try:
            truth = [float(s) for s in args.truth_scales.split(",")]
        except ValueError:
            fail(f"--truth-scales: not a list of numbers: {args.truth_scales!r}")
        if len(truth) != len(stories):
            fail(f"--truth-scales: {len(truth)} values but {args.csv} has {len(stories)} stories")
    panels = [roof_panel]
    if not stories:
        print(f"{args.csv}: no eta_* columns (estimator none?): roof panel only", file=sys.stderr)
    else:
        panels.append(eta_panel)
        forces = [c.get(n, np.zeros(1)) for n in ("contact_force_n", "device_force_truth_n")]
        if "eta_tmd" in c or any(np.any(f != 0) for f in forces):
            panels.append(device_panel)
        else:
            print(f"{args.csv}: device forces all zero: device panel skipped", file=sys.stderr)
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 1 + 3 * len(panels)), sharex=True,
                             squeeze=False)
    for ax, panel in zip(axes[:, 0], panels):
        if panel is eta_panel:
            panel(ax, t, c, got, stories, truth)
        else:
            panel(ax, t, c, got)
        ax.grid(alpha=0.4)
    axes[-1, 0].set_xlabel("time $t$ [s]")
    fig.align_ylabels(axes[:, 0])
    axes[-1, 0].set_xlim(t[0], t[-1])
    fig.suptitle(args.title or os.path.basename(args.csv))
    fig.tight_layout()
    try:
        fig.savefig(out, dpi=DPI)
    except (OSError, ValueError) as e:
        fail(f"cannot write {out}: {e}")
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
