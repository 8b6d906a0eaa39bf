#!/usr/bin/python3
"""The twin decision's thresholds from undamaged runs (docs/twin.md section 4).

Runs `vines hil --mode twin` on undamaged truths of the campaign (tools/twin_campaign_cases.py:
healthy stories within 3 %, masses within 2 %, every record, the three devices) with one of the
decision's tests alone (the other's threshold out of reach, no restart; for the change test
the absolute test's statistics silenced too, by a model error of 1000, since the CSV shows the
leading test's), reads each story's statistic from the --csv (`stat_*`), and prints, per run and in quantiles,
the largest one-story statistic held for the hold time (2 s): the threshold for a false-alarm
rate P is its (1 - P) quantile. With --family during (or before, two during) it prints the same
for damaged runs: how far above the threshold the losses sit.

Usage: twin_calibrate.py [--test absolute|change] [--runs N] [--family undamaged]
                         [--false-alarm 1] [--vines PATH] [--records DIR] [--jobs N] [-- VINES_HIL_OPTIONS]
"""
import argparse
import concurrent.futures as cf
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import twin_campaign_cases as tc  # noqa: E402
from twin_benchmark import scene_text  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ALONE = {"absolute": ["--twin-threshold-change", "1e6", "--twin-threshold", "1e6", "--twin-suspect", "1e6"],
         "change": ["--twin-threshold", "1e6", "--twin-threshold-change", "1e-9", "--twin-suspect", "1e6",
                    "--twin-healthy-tolerance", "1e3", "--twin-mass-tolerance", "1e3"]}
HOLD_UPDATES = 40  # 2 s of 50 ms updates


def held_max(path):
    """(largest statistic held for the hold time, its story) of one run's --csv."""
    with open(path) as f:
        rows = list(csv.DictReader(f))[::50]
    st = np.array([[float(r[f"stat_{j}"]) for j in range(1, 11)] for r in rows])
    t1 = st.max(axis=1)
    if len(t1) <= HOLD_UPDATES:
        return 0.0, 0
    held = [t1[i:i + HOLD_UPDATES].min() for i in range(len(t1) - HOLD_UPDATES)]
    i = int(np.argmax(held))
    return float(held[i]), int(np.argmax(st[i:i + HOLD_UPDATES].min(axis=0)) + 1)


def run(args, case):
    with tempfile.TemporaryDirectory() as d:
        node, truth, out = (os.path.join(d, n) for n in ("node.toml", "truth.toml", "run.csv"))
        with open(node, "w") as f:
            f.write(scene_text(tc.building(case["device"], case["record"])))
        with open(truth, "w") as f:
            f.write(scene_text(case["truth"]))
        cmd = [args.vines, "hil", node, "--mode", "twin", "--truth", truth, "--sensors", "3,6,8,10",
               "--measure-noise-pct", "5", "--seed", str(case["seed"]), "--duration", f"{case['duration_s']:.3f}",
               "--csv", out] + ALONE[args.test] + args.extra
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode not in (0, 3):
            return case, None, p.stderr.strip()[-300:] or f"exit {p.returncode}"
        return (case,) + held_max(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--test", choices=sorted(ALONE), default="change")
    ap.add_argument("--family", default="undamaged")
    ap.add_argument("--runs", type=int, default=40)
    ap.add_argument("--false-alarm", type=float, default=1.0, help="percent")
    ap.add_argument("--vines", default=os.path.join(ROOT, "build", "release", "vines"))
    ap.add_argument("--records", default=os.environ.get("VINES_GROUND_MOTIONS",
                                                        os.path.join(ROOT, "..", "shared", "data", "ground_motions")))
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--seed", type=int, default=7, help="the campaign design's seed")
    args, args.extra = ap.parse_known_args()
    if not os.access(args.vines, os.X_OK):
        sys.exit(f"twin_calibrate.py: error: {args.vines}: not an executable (build it first)")
    if not os.path.isdir(args.records):
        sys.exit(f"twin_calibrate.py: error: {args.records}: no such folder of ground motions")
    if args.runs < 1 or not 0 < args.false_alarm < 100:
        sys.exit("twin_calibrate.py: error: --runs at least 1, --false-alarm a percentage in (0, 100)")
    recs = [tc.record_info(os.path.join(args.records, f), args.vines) for f in tc.RECORDS]
    todo = [c for c in tc.cases(recs, seed=args.seed) if c["family"] == args.family]
    if not todo:
        sys.exit(f"twin_calibrate.py: error: --family {args.family}: no such family in the campaign")
    todo = todo[::max(1, len(todo) // args.runs)][:args.runs]
    held, failed = [], 0
    with cf.ThreadPoolExecutor(max(1, args.jobs)) as pool:
        for case, value, story in pool.map(lambda c: run(args, c), todo):
            if value is None:
                failed += 1
                print(f"failed: {story}", file=sys.stderr)
                continue
            held.append(value)
            print(f"{case['device']:5s} {os.path.basename(case['record'])[:28]:28s} damaged {case['damaged']} "
                  f"loss {case['loss']:.2f}: held {value:9.2f} (story {story})", flush=True)
    if not held:
        return 1
    q = np.quantile(held, [0.5, 0.9, 0.95, 1 - args.false_alarm / 100])
    print(f"{args.test} test, {len(held)} {args.family} runs ({failed} failed): held statistic median {q[0]:.1f}, "
          f"p90 {q[1]:.1f}, p95 {q[2]:.1f}, max {max(held):.1f}; threshold for {args.false_alarm:g} % false "
          f"alarms: {q[3]:.1f}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
