#!/usr/bin/python3
"""Plot `vines sweep` outputs like the paper's Fig. 5, Fig. 10 and Table 2.

Usage: plot_studies.py SWEEP_DIR [SWEEP_DIR ...] [--out DIR]

Each SWEEP_DIR holds results.csv (and summary.json) from `vines sweep SPEC.toml --out DIR`.
The studies of all dirs are pooled and recognised by device and varied keys (columns
with a dot in their name), preferring the names of data/studies/*.toml. Writes into --out
(default: out/plots; not a sweep folder, which vines sweep owns) whatever the studies allow:
  fig5_clearance.png  x_r, E_r vs beta: VI NES at rest (clearance_vines), IC mean +- sd per
                      beta (ic_vines_vs_beta), TMD at rest line and TMD IC mean +- sd band
  fig10_damage.png    x_r, E_r vs eta_k (damage_vines, damage_tmd)
  ic_heatmap.png      x_r over the initial-condition grid (ic_vines, ic_tmd)
  records_bars.png    x_r, E_r per record, own and scaled PGA (records_vines, records_tmd)
  table2.md           the paper's Table 2 (rest_vines, rest_tmd, ic_vines, ic_tmd), also
                      printed to stdout
Figures without their studies are skipped with a note on stderr. Exit code 2, with a message
naming the path, on a missing directory or an unreadable results.csv / summary.json.
"""
import argparse
import csv
import json
import os
import sys

import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 150
LABEL = {"vines": "VI NES", "tmd": "TMD"}
COLOR = {"vines": "tab:red", "tmd": "tab:blue"}
RATIOS = (("x_r", "max top-floor displacement"), ("E_r", "cumulative elastic energy"))
PAPER_T2 = {("vines", "x_r"): (29.2, 26.0, 4.3), ("tmd", "x_r"): (13.1, 17.7, 6.0),
            ("vines", "E_r"): (67.2, 60.5, 7.4), ("tmd", "E_r"): (77.5, 76.2, 4.5)}


def fail(msg):
    print(f"plot_studies.py: error: {msg}", file=sys.stderr)
    sys.exit(2)


def note(msg):
    print(f"plot_studies.py: {msg}", file=sys.stderr)


def num(s):
    try:
        return float(s)
    except ValueError:
        return float("nan")


class Study:
    """The successful runs of one study, its summary block and its varied keys."""

    def __init__(self, name, device, rows, keys, summary):
        self.name, self.device, self.rows, self.summary = name, device, rows, summary
        self.varied = {k for k in keys if any(r.get(k, "") != "" for r in rows)}

    def col(self, key):
        return np.array([num(r[key]) for r in self.rows])

    def key(self, prefix):
        """The varied column whose name starts with prefix (e.g. 'vines.initial_position')."""
        return next((k for k in sorted(self.varied) if k.startswith(prefix)), None)


def load(path, studies):
    if not os.path.isdir(path):
        fail(f"sweep directory not found: {path}")
    csv_path, sum_path = os.path.join(path, "results.csv"), os.path.join(path, "summary.json")
    try:
        with open(csv_path, newline="") as fh:
            reader = csv.DictReader(fh)
            rows, header = list(reader), reader.fieldnames or []
    except (OSError, csv.Error, UnicodeDecodeError) as e:
        fail(f"cannot read {csv_path}: {e}")
    missing = {"study", "device", "x_r", "E_r"} - set(header)
    if missing:
        fail(f"{csv_path}: missing column(s) {', '.join(sorted(missing))}")
    summary = {}
    if os.path.exists(sum_path):
        try:
            with open(sum_path) as fh:
                summary = {s.get("name"): s for s in json.load(fh).get("studies", [])}
        except (OSError, ValueError, AttributeError) as e:
            fail(f"cannot read {sum_path}: {e}")
    else:
        note(f"no {sum_path}: statistics are computed from results.csv")
    keys = [h for h in header if "." in h]
    failed = [r for r in rows if r.get("error")]
    if failed:
        note(f"{csv_path}: skipping {len(failed)} failed run(s)")
    # Degraded runs (status column, docs/model.md "Run status") are left out as the summary does.
    degraded = [r for r in rows if r.get("status") == "degraded"]
    if degraded:
        note(f"{csv_path}: skipping {len(degraded)} degraded run(s)")
    by_name = {}
    for r in rows:
        if (not r.get("error") and r.get("status", "ok") != "degraded" and np.isfinite(num(r["x_r"]))
                and np.isfinite(num(r["E_r"]))):
            by_name.setdefault(r["study"], []).append(r)
    for name, rs in by_name.items():
        if name in studies:
            note(f"study {name} in {path} ignored: already read from another directory")
            continue
        studies[name] = Study(name, rs[0]["device"], rs, keys, summary.get(name, {}))


def pick(studies, device, test, prefer=()):
    """The study of this device whose varied-key set passes test; names in prefer first."""
    found = [s for s in studies.values() if s.device == device and test(s.varied)]
    found.sort(key=lambda s: list(prefer).index(s.name) if s.name in prefer else len(prefer))
    return found[0] if found else None


def no_grid(v):
    return not v


def ic_only(device):
    return lambda v: bool(v) and all(k.startswith(device + ".initial_") for k in v)


def stats(a):
    a = np.asarray(a, float)
    return a.mean(), (a.std(ddof=1) if a.size > 1 else 0.0)


def beta_groups(s):
    """[(beta, {ratio: (mean, sd)})] from summary.json's groups, else from the rows."""
    g = s.summary.get("groups") if s.summary.get("group_by") == "vines.beta" else None
    if g:
        return sorted((float(x["value"]), {r: (x[r]["mean"], x[r]["sd"]) for r, _ in RATIOS})
                      for x in g)
    beta = s.col("vines.beta")
    return [(b, {r: stats(s.col(r)[beta == b]) for r, _ in RATIOS}) for b in np.unique(beta)]


def finish(fig, out, name, written):
    path = os.path.join(out, name)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    written.append(path)


def panels(ncols=2, nrows=1, size=(12, 4.8), **kw):
    fig, axs = plt.subplots(nrows, ncols, figsize=size, constrained_layout=True, squeeze=False,
                            **kw)
    for ax in axs.flat:
        ax.grid(True, alpha=0.35)
    return fig, axs


def fig5(studies, out, written):
    rest = pick(studies, "vines", lambda v: v == {"vines.beta"}, ["clearance_vines"])
    ic = pick(studies, "vines", lambda v: "vines.beta" in v and any(
        k.startswith("vines.initial_") for k in v), ["ic_vines_vs_beta"])
    if not rest and not ic:
        return note("fig5_clearance.png skipped: no VI NES study varying vines.beta")
    tmd = pick(studies, "tmd", no_grid, ["clearance_tmd_reference", "rest_tmd"])
    tmd_ic = pick(studies, "tmd", ic_only("tmd"), ["ic_tmd"])
    fig, axs = panels(size=(12, 5.6))
    for ax, (r, what), tag in zip(axs[0], RATIOS, "ab"):
        if tmd_ic:
            m, sd = stats(100 * tmd_ic.col(r))
            ax.axhspan(m - sd, m + sd, color="0.6", alpha=0.35, lw=0,
                       label=f"TMD, IC mean ± σ ({m:.1f} ± {sd:.1f} %)")
        if tmd:
            v = 100 * tmd.col(r).mean()
            ax.axhline(v, color=COLOR["tmd"], ls="--", lw=1.4, label=f"TMD at rest ({v:.1f} %)")
        if rest:
            b, y = rest.col("vines.beta"), 100 * rest.col(r)
            o = np.argsort(b)
            ax.plot(b[o], y[o], "o--", color=COLOR["vines"], mfc="white", ms=5,
                    label=f"VI NES at rest (best {y.max():.1f} % at β = {b[np.argmax(y)]:.2f})")
        if ic:
            g = beta_groups(ic)
            b = [x[0] for x in g]
            m = np.array([100 * x[1][r][0] for x in g])
            sd = np.array([100 * x[1][r][1] for x in g])
            ax.errorbar(b, m, yerr=sd, fmt="s-", color="darkred", ms=5, capsize=3, lw=1.2,
                        label="VI NES, IC mean ± σ")
        ax.set(xlabel="clearance β = b / 2R [-]", ylabel=f"{r} [%]",
               title=f"({tag}) reduction of the {what}")
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    fig.suptitle("Fig. 5 — clearance study, El Centro NS 1940")
    finish(fig, out, "fig5_clearance.png", written)


def fig10(studies, out, written):
    found = {d: pick(studies, d, lambda v: v == {"frame.stiffness_scale"}, ["damage_" + d])
             for d in LABEL}
    if not any(found.values()):
        return note("fig10_damage.png skipped: no study varying frame.stiffness_scale")
    fig, axs = panels()
    for ax, (r, what), tag in zip(axs[0], RATIOS, "ab"):
        ax.axhline(0, color="k", lw=0.8)
        for d, s in found.items():
            if s:
                eta, y = s.col("frame.stiffness_scale"), 100 * s.col(r)
                o = np.argsort(eta)
                ax.plot(eta[o], y[o], "o-" if d == "vines" else "s-", color=COLOR[d], ms=4,
                        label=LABEL[d])
        ax.set(xlabel="stiffness ratio η_k = k / k_nominal [-]", ylabel=f"{r} [%]",
               title=f"({tag}) reduction of the {what}")
        ax.legend(fontsize=9)
    fig.suptitle("Fig. 10 — sensitivity to the frame's stiffness loss (devices at nominal design)")
    finish(fig, out, "fig10_damage.png", written)


def ic_grid(s, device):
    """(x centres, y centres, Z[y, x]) of x_r [%] and the x, y column names."""
    kx, ky = s.key(device + ".initial_position"), s.key(device + ".initial_velocity")
    if not kx or not ky:
        return None
    x, y, z = s.col(kx), s.col(ky), 100 * s.col("x_r")
    ux, uy = np.unique(x), np.unique(y)
    Z = np.full((uy.size, ux.size), np.nan)
    Z[np.searchsorted(uy, y), np.searchsorted(ux, x)] = z
    return ux, uy, Z, kx, ky


def axis_label(key, what):
    if key.endswith("/gap"):
        return f"initial {what} / gap [-]"
    if key.endswith("/vmax"):
        return f"initial {what} / v_max [-]"
    return f"initial {what} [{'m' if what == 'position' else 'm/s'}]"


def ic_heatmap(studies, out, written):
    grids = {}
    for d in LABEL:
        s = pick(studies, d, ic_only(d), ["ic_" + d])
        g = ic_grid(s, d) if s else None
        if s and not g:
            note(f"ic_heatmap.png: study {s.name} lacks an initial position or velocity column")
        if g:
            grids[d] = (s, g)
    if not grids:
        return note("ic_heatmap.png skipped: no study over the initial-condition grid")
    allz = np.concatenate([g[2].ravel() for _, g in grids.values()])
    lo, hi = np.nanmin(allz), np.nanmax(allz)
    fig, axs = panels(len(grids), size=(5.6 * len(grids) + 1, 5.2))
    for ax, (d, (s, (ux, uy, Z, kx, ky))) in zip(axs[0], grids.items()):
        ax.grid(False)
        im = ax.pcolormesh(ux, uy, Z, shading="nearest", cmap="viridis", vmin=lo, vmax=hi)
        m, sd = stats(100 * s.col("x_r"))
        if kx.endswith("/gap") and ky.endswith("/vmax"):
            rest = (-1.0, 0.0) if d == "vines" else (0.0, 0.0)
            ax.plot(*rest, "*", color="white", mec="k", ms=14, label="at rest (reference case)")
            ax.legend(fontsize=8, loc="upper right")
        ax.set(xlabel=axis_label(kx, "position"), ylabel=axis_label(ky, "velocity"),
               title=f"{LABEL[d]} ({s.name}, {Z.size} runs): x_r = {m:.1f} ± {sd:.1f} %")
    fig.colorbar(im, ax=axs[0].tolist(), label="x_r [%]", shrink=0.9)
    fig.suptitle("Initial-condition sensitivity of x_r, El Centro NS 1940\n"
                 "position as a fraction of the VI NES gap (free travel; the same grid "
                 "applied to the TMD mass), velocity as a fraction of v_max (bare frame's "
                 "peak top-floor velocity)", fontsize=10)
    finish(fig, out, "ic_heatmap.png", written)


def short_names(paths):
    """File name -> 'name year' plus the fewest distinguishing tokens among same prefixes."""
    toks = {p: os.path.splitext(p)[0].split("_") for p in paths}
    out = {}
    for p, t in toks.items():
        same = [u for u in toks.values() if u[:2] == t[:2]]
        common = set.intersection(*(set(u[2:]) for u in same))
        own = [w for w in t[2:] if w not in common]
        others = [[w for w in u[2:] if w not in common] for u in same if u is not t]
        k = 0
        while k < len(own) and any(o[:k] == own[:k] for o in others):
            k += 1
        out[p] = " ".join(t[:2] + own[:k])
    return out


def records_bars(studies, out, written):
    found = {d: pick(studies, d, lambda v: "record.path" in v, ["records_" + d]) for d in LABEL}
    found = {d: s for d, s in found.items() if s}
    if not found:
        return note("records_bars.png skipped: no study varying record.path")
    recs, pgas = [], []
    for s in found.values():
        for r in s.rows:
            recs += [r["record.path"]] if r["record.path"] not in recs else []
            p = r.get("record.pga_g", "") or "unset"
            pgas += [p] if p not in pgas else []
    pgas.sort(key=lambda p: -1 if p == "unset" else num(p))
    names, x, w = short_names(recs), np.arange(len(recs)), 0.8 / len(found)
    fig, axs = panels(len(pgas), 2, size=(6.5 * len(pgas) + 1, 9), sharey="row")
    for j, p in enumerate(pgas):
        title = "own PGA" if p == "unset" else f"scaled to PGA {num(p):.3f} g" + (
            " (El Centro's)" if abs(num(p) - 0.3487) < 1e-3 else "")
        for i, (r, what) in enumerate(RATIOS):
            ax = axs[i, j]
            ax.axhline(0, color="k", lw=0.8)
            for k, (d, s) in enumerate(found.items()):
                val = {q["record.path"]: 100 * num(q[r]) for q in s.rows
                       if (q.get("record.pga_g", "") or "unset") == p}
                ax.bar(x + (k - (len(found) - 1) / 2) * w, [val.get(q, np.nan) for q in recs],
                       w, color=COLOR[d], label=LABEL[d])
            ax.set_xticks(x, [names[q] for q in recs], rotation=35, ha="right", fontsize=8)
            ax.set(ylabel=f"{r} [%] ({what})")
            ax.set_title(f"({chr(97 + i * len(pgas) + j)}) {r} — {title}", fontsize=10)
            ax.legend(fontsize=8)
    fig.suptitle("Robustness over records — devices designed on El Centro NS 1940")
    finish(fig, out, "records_bars.png", written)


def table2(studies, out, written):
    rest = {d: pick(studies, d, no_grid, ["rest_" + d, "clearance_tmd_reference"]) for d in LABEL}
    ic = {d: pick(studies, d, ic_only(d), ["ic_" + d]) for d in LABEL}
    if not rest["vines"] and not any(ic.values()):
        return note("table2.md skipped: no rest_vines, ic_vines or ic_tmd study")

    def f(v):
        return "–" if v is None else f"{100 * v:.1f} %"

    lines = ["# Table 2 — performance sensitivity to initial conditions (El Centro NS 1940)", "",
             "| Device | Reduction ratio | Reference case | Average | Standard deviation "
             "| Paper: reference | Paper: average | Paper: σ |",
             "|---|---|---|---|---|---|---|---|"]
    for r, _ in RATIOS:
        for d in ("vines", "tmd"):
            ref = rest[d].col(r).mean() if rest[d] else None
            m, sd = stats(ic[d].col(r)) if ic[d] else (None, None)
            pr = " | ".join(f"{v:.1f} %" for v in PAPER_T2[d, r])
            lines.append(f"| {LABEL[d]} | {r} | {f(ref)} | {f(m)} | {f(sd)} | {pr} |")
    src = [f"{s.name} ({len(s.rows)} run{'s' * (len(s.rows) > 1)})" for s in list(rest.values()) + list(ic.values()) if s]
    lines += ["", "Reference case: device at rest. Average and sample standard deviation over "
              "the initial-condition grid. Sources: " + ", ".join(src) + ".", ""]
    text = "\n".join(lines)
    path = os.path.join(out, "table2.md")
    with open(path, "w") as fh:
        fh.write(text)
    print(text)
    written.append(path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dirs", nargs="+", metavar="SWEEP_DIR")
    ap.add_argument("--out", help="output directory (default: out/plots)")
    a = ap.parse_args(argv)
    studies = {}
    for d in a.dirs:
        load(d, studies)
    out = a.out or "out/plots"
    os.makedirs(out, exist_ok=True)
    written = []
    for fn in (fig5, fig10, ic_heatmap, records_bars, table2):
        fn(studies, out, written)
    for p in written:
        print(p)
    if not written:
        note("nothing to plot in the given directories")


if __name__ == "__main__":
    main()
