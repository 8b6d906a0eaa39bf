#!/usr/bin/env python3
"""The contact tolerance table of data/studies/tolerance.toml.

Reads DIR/results.csv of `vines sweep data/studies/tolerance.toml --out DIR`
and prints, for each loop.contact_rtol, the grid's statistics of x_r and E_r
(mean and sample sd over its ok runs, in %), how far each statistic is from
the tightest tolerance's, and the per-run spread against the tightest
tolerance (median and 90th percentile of |x_r - x_r(tightest)| over the
runs ok at both), and the largest energy balance residual (when the runs
computed it). Exits 1 naming the file when it is missing, has no such
study, or no ok run.

    /usr/bin/python3 tools/tolerance_table.py DIR [--study ic_vines_rtol]
"""
import argparse
import csv
import statistics
import sys
from pathlib import Path

KEY = "loop.contact_rtol"


def fail(msg):
    print(f"tolerance_table: {msg}", file=sys.stderr)
    sys.exit(1)


def percentile(values, p):
    v = sorted(values)
    if not v:
        return float("nan")
    k = (len(v) - 1) * p
    lo = int(k)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="the sweep's output folder (holds results.csv)")
    ap.add_argument("--study", default="ic_vines_rtol", help="the study's name (default: %(default)s)")
    args = ap.parse_args()
    path = Path(args.dir) / "results.csv"
    try:
        with open(path, newline="") as f:
            rows = [r for r in csv.DictReader(f) if r.get("study") == args.study]
    except OSError as e:
        fail(f"{path}: cannot read: {e.strerror}")
    if not rows:
        fail(f"{path}: no run of study '{args.study}'")
    if KEY not in rows[0]:
        fail(f"{path}: no column '{KEY}' (not a tolerance study)")
    others = [c for c in rows[0] if c.startswith(("vines.", "tmd.", "record."))]
    by_tol, residual = {}, {}
    for r in rows:
        if r.get("status") != "ok":
            continue
        point = tuple(r[c] for c in others)
        tol = float(r[KEY])
        by_tol.setdefault(tol, {})[point] = (100 * float(r["x_r"]), 100 * float(r["E_r"]))
        if r.get("energy_balance_residual"):
            residual[tol] = max(residual.get(tol, 0.0), abs(float(r["energy_balance_residual"])))
    if not by_tol:
        fail(f"{path}: no ok run in study '{args.study}'")
    tight = min(by_tol)
    ref = by_tol[tight]
    ref_x = statistics.mean(v[0] for v in ref.values())
    ref_e = statistics.mean(v[1] for v in ref.values())
    print(f"| contact_rtol | runs ok | x_r % mean +- sd | E_r % mean +- sd | mean x_r - tightest | "
          f"mean E_r - tightest | per-run abs dx_r median / p90 | per-run abs dE_r median / p90 | "
          f"max energy residual |")
    print("|---|---|---|---|---|---|---|---|---|")
    for tol in sorted(by_tol, reverse=True):
        runs = by_tol[tol]
        xs = [v[0] for v in runs.values()]
        es = [v[1] for v in runs.values()]
        mx, me = statistics.mean(xs), statistics.mean(es)
        sx = statistics.stdev(xs) if len(xs) > 1 else 0.0
        se = statistics.stdev(es) if len(es) > 1 else 0.0
        both = [p for p in runs if p in ref]
        dx = [abs(runs[p][0] - ref[p][0]) for p in both]
        de = [abs(runs[p][1] - ref[p][1]) for p in both]
        print(f"| {tol:g} | {len(runs)} | {mx:.2f} +- {sx:.2f} | {me:.2f} +- {se:.2f} | {mx - ref_x:+.3f} | "
              f"{me - ref_e:+.3f} | {percentile(dx, 0.5):.2g} / {percentile(dx, 0.9):.2g} | "
              f"{percentile(de, 0.5):.2g} / {percentile(de, 0.9):.2g} | "
              f"{format(residual[tol], '.2g') if tol in residual else 'not computed'} |")


if __name__ == "__main__":
    main()
