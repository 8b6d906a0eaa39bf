#!/usr/bin/python3
"""The twin monitor's benchmark campaign (docs/twin.md section 8, issue 52).

Runs `vines hil NODE_SCENE --mode twin --truth TRUTH` over: the three devices (bare frame, TMD,
VI NES: the nominal Table 1 frame, as data/scenes/elcentro_{bare,tmd,vines}.toml); every record
of the ground-motion folder, each run to max(40 s, its 95 % Arias time + 10 s) (Arias over the
whole record; Mexico City SCT, whose strong motion lies after 40 s, on lines of its own); truths
that are not their drawing (each story's stiffness within 3 %, each floor's mass within 2 %, VI
NES eps within 2 %, the sphere or the TMD started elsewhere), undamaged, or losing 3, 5, 10 or
20 % of one story at an onset drawn in the record's 25-75 % Arias span (every story and loss,
spread over the records and noise seeds by a sampled design, deterministic from --design-seed),
two stories 10 % during the record, one story 5 or 10 % before it (no baseline); buildings
commissioned on three other earthquakes, then run from their baseline, undamaged and with a
story lost 5 or 10 % before the record (tools/twin_campaign_baseline.py); detuned TMDs; a stuck
sphere. Sensors: the
ground as the node's input and floors 3, 6, 8, 10 at 1 kHz, 5 % RMS noise.

Prints the planned run count and an estimated time first, then one table: detection,
localisation (and within 20 s of onset), size error and share within 1 / 1.5 / 2 points, onset
error and share within 2 s, delay, false alarms with a 95 % Wilson interval, roof NRMSE, host
time per step, each figure beside its target (issue 52) with a pass/fail mark; the devices'
health (VI NES impulse within 25 %, stuck sphere reported, never on a moving one; TMD detuned);
the failed runs, counted and listed. With --calibrate, undamaged runs only and their largest
final loss estimate. Options the tool does not know go to `vines hil` (e.g. --twin-threshold).

Usage: twin_benchmark.py [--vines PATH] [--records DIR] [--jobs N] [--quick] [--seeds N]
                         [--undamaged N] [--replicates N] [--design-seed S] [--only FAMILIES]
                         [--only-records NAMES] [--limit N] [--duration S] [--commission N | --baseline-dir DIR]
                         [--bound-located 5=P,10=P] [--bound-located-baseline 5=P,10=P]
                         [--calibrate] [--json FILE] [--sensors LIST] [--noise-pct P] [--plan]
Exit 2 with a message naming the input on a missing program, folder, record or baseline file.
"""
import argparse
import collections
import concurrent.futures as cf
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import twin_campaign_baseline as cb  # noqa: E402
import twin_campaign_cases as cc  # noqa: E402
import twin_campaign_table as ct  # noqa: E402
from twin_campaign_cases import (DEVICES, GAP_M, RECORDS, ROOT, TABLE1_K_MN, TABLE1_MASS_T, TMD_C, TMD_K,  # noqa: E402,F401
                                 building)

CPU_S_PER_RECORD_S = 2.5 / 40  # a twin run's CPU per second of record (2-core VM, 1 kHz)
FAMILIES = ("undamaged", "during", "two during", "before", "undamaged baseline", "before baseline", "detuned",
            "stuck")


def fail(msg):
    print(f"twin_benchmark.py: error: {msg}", file=sys.stderr)
    sys.exit(2)


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return repr(float(v)) if isinstance(v, float) else str(v)


def scene_text(tables):
    return "".join(f"[{name}]\n" + "".join(f"{k} = {toml_value(v)}\n" for k, v in keys.items()) + "\n"
                   for name, keys in tables.items() if keys is not None)


def run(args, tmp, i, case):
    """One `vines hil` twin run: the case with its report (twin, steps, wall) or its error."""
    node = os.path.join(tmp, f"node_{i}.toml")
    tpath = os.path.join(tmp, f"truth_{i}.toml")
    with open(node, "w") as f:
        f.write(scene_text(building(case["device"], case["record"])))
    with open(tpath, "w") as f:
        f.write(scene_text(case["truth"]))
    duration = args.duration or case["duration_s"]
    cmd = [args.vines, "hil", node, "--mode", "twin", "--truth", tpath, "--sensors", args.sensors,
           "--measure-noise-pct", str(args.noise_pct), "--seed", str(case["seed"]), "--json",
           "--timeout", str(args.timeout), "--duration", f"{duration:.3f}"]
    if case.get("baseline"):
        cmd += ["--baseline", case["baseline"]]
    if case.get("commission"):
        cmd += ["--commission", case["commission"]]
    cmd += args.extra
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=args.run_timeout)
    except subprocess.TimeoutExpired:
        return dict(case=case, error=f"still running after {args.run_timeout:g} s (--run-timeout)")
    finally:
        for path in (node, tpath):
            os.remove(path)
    if p.returncode not in (0, 3):  # the scenes' temporary names left out: one message, one line of the list
        err = re.sub(r"<(node|truth)>:\d+:", r"<\1>:", p.stderr.strip().replace(tpath, "<truth>").replace(node, "<node>"))
        return dict(case=case, error=err or f"exit {p.returncode}")
    try:
        r = json.loads(p.stdout)
        return dict(case=case, twin=r["twin"], steps=r["steps"], wall=r["wall_time_s"])
    except (ValueError, KeyError) as e:
        return dict(case=case, error=f"unreadable report ({e}): {p.stdout[:200]!r}")


def limited(todo, n):
    """n runs taken round-robin over the families (a small campaign that still has each)."""
    by = collections.OrderedDict()
    for c in todo:
        by.setdefault(c["family"], []).append(c)
    out = []
    while len(out) < n and any(by.values()):
        for fam in by:
            if by[fam] and len(out) < n:
                out.append(by[fam].pop(0))
    return out


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vines", default=os.path.join(ROOT, "build", "release", "vines"))
    ap.add_argument("--records", default=os.environ.get("VINES_GROUND_MOTIONS",
                                                        os.path.join(ROOT, "..", "shared", "data", "ground_motions")))
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--seeds", type=int, default=5, help="noise seeds 1..N, spread over the runs")
    ap.add_argument("--undamaged", type=int, help="undamaged truths per device and record (15; quick 3)")
    ap.add_argument("--replicates", type=int,
                    help="runs per device, story and loss during the record (10; quick 0: each once over the devices)")
    ap.add_argument("--design-seed", type=int, default=20261125, help="the design's seed: truths, onsets, assignment")
    ap.add_argument("--only", help="families, comma-separated: " + ", ".join(FAMILIES))
    ap.add_argument("--devices", help="devices, comma-separated: " + ", ".join(DEVICES))
    ap.add_argument("--only-records", help="runs on these records only, comma-separated parts of their file names "
                                           "(the same runs as the whole campaign's on them)")
    ap.add_argument("--limit", type=int, help="the first N runs, round-robin over the families")
    ap.add_argument("--duration", type=float, help="S seconds of every record instead of the Arias rule")
    ap.add_argument("--timeout", type=float, default=60, help="vines hil --timeout: longest wait for the node [s]")
    ap.add_argument("--run-timeout", type=float, default=900, help="a run still going after S seconds has failed")
    ap.add_argument("--sensors", default="3,6,8,10")
    ap.add_argument("--noise-pct", type=float, default=5)
    ap.add_argument("--quick", action="store_true", help="about 150 runs: each story and loss once over the devices")
    ap.add_argument("--calibrate", action="store_true", help="undamaged truths only; their largest estimates")
    ap.add_argument("--commission", type=int, help="healthy buildings per device commissioned on three other "
                    "earthquakes, then run from their baseline (tools/twin_campaign_baseline.py; 3, quick 1; 0: none)")
    ap.add_argument("--baseline-dir", help="the baselines instead from DIR (twin_campaign_baseline.from_dir)")
    ap.add_argument("--bound-located", help="loss=share of the bound tool's one-story GLRT, e.g. 5=0.27,10=0.95: "
                                            "the before-the-record rows' target is 0.9 x it")
    ap.add_argument("--bound-located-baseline", help="the same for the rows run from a baseline, e.g. 5=0.99")
    ap.add_argument("--plan", action="store_true", help="print the planned runs and the time estimate, run nothing")
    ap.add_argument("--json", help="write every run's case and twin report to FILE")
    args, args.extra = ap.parse_known_args(argv)
    return args


def prepare(args, tmp):
    """The checked inputs and the runs: (records' info, cases, commissioning runs: their baselines
    written in tmp). Exits 2 naming what is missing."""
    if not args.plan and not os.access(args.vines, os.X_OK):
        fail(f"{args.vines}: not an executable (build it: cmake --preset release && cmake --build --preset release)")
    if not os.path.isdir(args.records):
        fail(f"{args.records}: no such folder of ground motions (--records, or VINES_GROUND_MOTIONS)")
    records = []
    for name in RECORDS:
        path = os.path.join(args.records, name)
        if not os.path.isfile(path):
            fail(f"{path}: no such record (the campaign runs every record of RECORDS in {args.records})")
        try:
            records.append(cc.record_info(path, args.vines))
        except Exception as e:  # the package's RecordError names the file and the reason
            fail(f"{path}: unreadable record: {e}")
    families = chosen(args.only, "--only", "family", FAMILIES)
    devices = chosen(args.devices, "--devices", "device", DEVICES)
    args.bound = {"before": bound_shares(args.bound_located, "--bound-located"),
                  "before baseline": bound_shares(args.bound_located_baseline, "--bound-located-baseline")}
    todo = cc.cases(records, quick=args.quick, seed=args.design_seed, seeds=args.seeds, calibrate=args.calibrate,
                    undamaged=args.undamaged, replicates=args.replicates, families=families)
    buildings = []
    wanted = not families or {"undamaged baseline", "before baseline"} & set(families)
    if args.baseline_dir and wanted and not args.calibrate:
        if not os.path.isdir(args.baseline_dir):
            fail(f"--baseline-dir {args.baseline_dir}: no such folder")
        buildings = cb.from_dir(args.baseline_dir, fail)
    elif wanted and not args.calibrate:
        n = args.commission if args.commission is not None else (1 if args.quick else 3)
        if n < 0:
            fail(f"--commission {n}: a count of buildings per device, 0 for none")
        missing = [m for m in cb.COMMISSION_RECORDS if m not in {r["name"] for r in records}]
        if n and missing:
            fail(f"--commission: the commissioning records {', '.join(missing)} are not in {args.records}")
        buildings = cb.drawn(records, tmp, buildings=n, seed=args.design_seed, seeds=args.seeds) if n else []
    if buildings:
        todo += [c for c in cb.cases(buildings, records, quick=args.quick, seed=args.design_seed, seeds=args.seeds,
                                     fail=fail) if not families or c["family"] in families]
    if devices:
        todo = [c for c in todo if c["device"] in devices]
    if args.only_records:
        parts = [x.strip() for x in args.only_records.split(",") if x.strip()]
        for x in parts:
            if not any(x in name for name in RECORDS):
                fail(f"--only-records {x}: no record's file name holds it ({', '.join(RECORDS)})")
        todo = [c for c in todo if any(x in os.path.basename(c["record"]) for x in parts)]
    if args.limit:
        todo = limited(todo, args.limit)
    kept = {c.get("baseline") for c in todo}
    commission = [c for b in buildings if b["baseline"] in kept for c in b["commission"]]
    return records, todo, commission


def chosen(text, flag, what, names):
    """A comma-separated list of names (None without it); exits 2 on one that is not in names."""
    if not text:
        return None
    out = [x.strip() for x in text.split(",") if x.strip()]
    for x in out:
        if x not in names:
            fail(f"{flag} {x}: not a {what} ({', '.join(names)})")
    return out


def bound_shares(text, flag):
    """--bound-located's LOSS_PCT=SHARE,... as {loss: share}; None without it."""
    if not text:
        return None
    try:
        return {int(k) / 100: float(v) for k, v in (x.split("=") for x in text.split(","))}
    except ValueError:
        fail(f"{flag} {text}: expected LOSS_PCT=SHARE,..., e.g. 5=0.27,10=0.95")


def estimate(args, todo):
    """(CPU seconds, wall minutes) the runs should take, from CPU_S_PER_RECORD_S."""
    cpu = sum(CPU_S_PER_RECORD_S * (args.duration or c["duration_s"]) for c in todo)
    return cpu, cpu / max(1, min(args.jobs, os.cpu_count() or 1)) / 60


def json_entry(r):
    c = r["case"]
    return dict(family=c["family"], label=c["label"], device=c["device"], record=os.path.basename(c["record"]),
                damaged=c["damaged"], loss=c["loss"], truth_damage_time_s=c["onset_s"], healthy_scales=c["healthy"],
                masses_t=c["masses"], seed=c["seed"], duration_s=c["duration_s"], baseline=c.get("baseline"),
                twin=r.get("twin"), steps=r.get("steps"), wall_time_s=r.get("wall"), error=r.get("error"))


def commission(args, tmp, pool, runs):
    """The commissioning runs, each baseline's in turn (they add to its file), the baselines at
    once. A run the node refuses to add (its estimates leave what a building of this drawing can
    be: the report's caveat) is skipped and counted; any other failure exits 2 naming the run.
    Returns (the refused runs' messages, the baselines no run was added to)."""
    by = collections.OrderedDict()
    for c in runs:
        by.setdefault(c["commission"], []).append(c)

    def one(k, cs):
        refused = []
        for j, c in enumerate(cs):
            r = run(args, tmp, f"commission_{k}_{j}", c)
            if "error" in r and "is not added to it" in r["error"]:
                refused.append(f"{os.path.basename(c['commission'])} on {os.path.basename(c['record'])}")
            elif "error" in r:
                fail(f"commissioning {c['commission']} on {os.path.basename(c['record'])} failed: {r['error']}")
        return refused

    refused = [m for ms in pool.map(lambda kc: one(*kc), enumerate(by.values())) for m in ms]
    return refused, {path for path in by if not os.path.isfile(path)}


def main(argv=None):
    args = parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        return campaign(args, tmp)


def campaign(args, tmp):
    records, todo, runs = prepare(args, tmp)
    cpu, minutes = estimate(args, todo + runs)
    count = collections.Counter(c["family"] for c in todo + runs)
    print(f"twin_benchmark.py: planned {len(todo) + len(runs)} runs ({', '.join(f'{n} {f}' for f, n in count.items())}; "
          f"{sum(c['sct'] for c in todo)} on SCT); estimated {cpu / 60:.0f} CPU min, about {minutes:.0f} min "
          f"on {args.jobs} jobs", file=sys.stderr, flush=True)
    if args.plan:
        for r in records:
            print(f"{r['name']}: {r['length_s']:.1f} s, Arias 5/25/75/95 % at {r['t05']:.1f} / {r['t25']:.1f} / "
                  f"{r['t75']:.1f} / {r['t95']:.1f} s, runs {r['duration_s']:.1f} s")
        return 0
    results, start = [], time.monotonic()
    with cf.ThreadPoolExecutor(max(1, args.jobs)) as pool:
        if runs:
            refused, empty = commission(args, tmp, pool, runs)
            todo = [c for c in todo if c.get("baseline") not in empty]
            print(f"twin_benchmark.py: {len(runs)} commissioning runs, {len(refused)} not added (a caveat: "
                  f"{'; '.join(refused) or 'none'}), {len(empty)} baselines left empty and their runs left out, "
                  f"{(time.monotonic() - start) / 60:.1f} min", file=sys.stderr, flush=True)
        futures = [pool.submit(run, args, tmp, i, c) for i, c in enumerate(todo)]
        for n, f in enumerate(cf.as_completed(futures), 1):
            results.append(f.result())
            if n % 20 == 0 or n == len(todo):
                print(f"twin_benchmark.py: {n}/{len(todo)} runs, {(time.monotonic() - start) / 60:.1f} min",
                      file=sys.stderr, flush=True)
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_used = used.ru_utime + used.ru_stime
    order = {id(c): i for i, c in enumerate(todo)}
    simulated = sum(args.duration or r["case"]["duration_s"] for r in results if "twin" in r)
    results.sort(key=lambda r: order[id(r["case"])])
    errors = [r for r in results if "error" in r]
    if args.json:
        with open(args.json, "w") as f:
            json.dump([json_entry(r) for r in results], f)
    print(f"twin benchmark: sensors {args.sensors} at 1 kHz, noise {args.noise_pct:g} % RMS, {len(records)} records "
          f"(each to max(40 s, Arias 95 % + 10 s)), healthy stories within {cc.HEALTHY_K_PCT:g} %, masses within "
          f"{cc.MASS_PCT:g} %, {len(results)} runs ({len(errors)} failed), "
          f"{(time.monotonic() - start) / 60:.1f} min on {args.jobs} jobs ({40 * cpu_used / max(1e-9, simulated):.2f} s "
          f"CPU per 40 s of record run; estimated {40 * CPU_S_PER_RECORD_S:g}), design seed {args.design_seed}")
    ct.print_all(results, args.bound)
    if args.calibrate:
        worst = sorted(max(1 - e for e in r["twin"]["eta_k"]) for r in results if "twin" in r)
        if worst:
            print(f"undamaged: largest final loss estimate of any story: median {statistics.median(worst):.4f}, "
                  f"p99 {worst[min(len(worst) - 1, int(0.99 * len(worst)))]:.4f}, max {worst[-1]:.4f}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
