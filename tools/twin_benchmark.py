#!/usr/bin/python3
"""The twin monitor's benchmark campaign (docs/twin.md section 8).

Runs `vines hil NODE_SCENE --mode twin --truth TRUTH` over: the three devices
(bare frame, TMD, VI NES: the node scenes data/scenes/elcentro_{bare,tmd,vines}.toml);
every record in the ground-motion folder; truths that are undamaged (masses
off by up to 2 % per floor, VI NES eps off by up to 2 %, the sphere or the TMD
started elsewhere), have lost 5, 10 or 20 % of one story (every story), or
10 % of two; detuned TMDs (frequency 10 % low and high); and noise seeds.
Sensors: the ground as the node's input and floors 3, 6, 8, 10, 5 % RMS noise.
Prints one table: detection, localisation, size error, delay after strong
motion, false alarms, roof NRMSE, host time per step; with --calibrate, the
undamaged runs' largest loss estimate (the alarm's 3 % floor comes from it).

Usage: twin_benchmark.py [--vines PATH] [--records DIR] [--jobs N] [--seeds N]
                         [--undamaged N] [--duration S] [--quick] [--calibrate]
                         [--json FILE] [--sensors LIST] [--noise-pct P]
Exit 2 with a message naming the input on a missing program, folder or scene.
"""
import argparse
import concurrent.futures as cf
import json
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TABLE1_MASS_T = [179, 170, 161, 152, 143, 134, 125, 116, 107, 98]
TABLE1_K_MN = [62.47, 52.26, 56.14, 53.02, 49.91, 46.79, 43.67, 40.55, 37.43, 34.31]
TMD_K, TMD_C = 488732.6137915217, 44133.36142032142  # the Den Hartog design of elcentro_tmd.toml
GAP_M = 0.4148  # the VI NES sphere's free travel each side of the box centre (elcentro_vines.toml)
RECORDS = {  # file -> [record] keys (formats as data/studies/records.toml)
    "elcentro_1940_ns_2688pts_dt002_time_g.dat": {"format": "time-accel", "units": "g"},
    "elcentro_1940_ns_peknold_dt002.at2": {"format": "at2"},
    "elcentro_1940_ns_peer_legacy_I-ELC180_dt001.at2": {"format": "at2"},
    "elcentro_1940_ns_peer_nga_west2_rsn6_I-ELC180.at2": {"format": "at2"},
    "taft_1952_kern_county_TAF021_nga_west2_rsn15.at2": {"format": "at2"},
    "kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2": {"format": "at2"},
    "northridge_1994_rinaldi_228_nga_rsn1063.at2": {"format": "at2"},
    "northridge_1994_sylmar_county_hospital_ns_time_ms2.dat": {"format": "time-accel", "units": "m/s2"},
    "lomaprieta_1989_corralitos_CLS000_nga_west2_rsn753.at2": {"format": "at2"},
    "mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt": {"format": "time-accel", "units": "g", "column": 2},
}


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


def building(device, record, *, masses=None, scales=None, eps=0.7, x0=0.0, tmd_k=None, tmd_x0=0.0):
    """A scene's tables: the Table 1 frame (masses, per-story scales), a device, a record."""
    frame = {"preset": "table1"}
    if masses:
        frame = {"preset": "custom", "masses_kg": [m * 1e3 for m in masses],
                 "stiffnesses_n_per_m": [k * 1e6 for k in TABLE1_K_MN], "damping": "stiffness",
                 "stiffness_damping_s": 0.0129}
    if scales:
        frame["stiffness_scales"] = scales
    t = {"scene": {"name": "twin_bench"}, "frame": frame, "device": {"kind": device}}
    if device != "none":
        t["device"]["mass_ratio"] = 0.05
    if device == "vines":
        t["vines"] = {"law": "kuwabara", "beta": 1.35, "eps": eps, "v_ref_mps": 0.5, "initial_position_m": x0}
    if device == "tmd":
        t["tmd"] = {"initial_position_m": tmd_x0}
        if tmd_k:
            t["tmd"].update({"k_n_per_m": tmd_k, "c_ns_per_m": TMD_C})
    t["record"] = dict({"path": record}, **RECORDS[os.path.basename(record)])
    t["loop"] = {"sensor_rate_hz": 1000.0}
    return t


def perturbed(rng, device, record, **kw):
    """A truth whose masses (and eps, and the device's start) are off the node's model."""
    masses = [m * (1 + 0.02 * rng.uniform(-1, 1)) for m in TABLE1_MASS_T]
    return building(device, record, masses=masses, eps=0.7 * (1 + 0.02 * rng.uniform(-1, 1)),
                    x0=0.8 * GAP_M * rng.uniform(-1, 1), tmd_x0=0.05 * rng.uniform(-1, 1), **kw)


def cases(args, records):
    """(label, device, record, truth tables, damaged stories, loss, seed) for every run."""
    rng = random.Random(20261125)
    losses = [0.10] if args.quick else [0.05, 0.10, 0.20]
    stories = [3, 8] if args.quick else range(1, 11)
    pairs = [] if args.quick else [(2, 7), (4, 9)]
    out = []
    for device in ("none", "tmd", "vines"):
        for rec in records:
            for seed in range(1, args.seeds + 1):
                for _ in range(args.undamaged):
                    out.append(("undamaged", device, rec, perturbed(rng, device, rec), [], 0.0, seed))
                if args.calibrate:
                    continue
                for s in stories:
                    for loss in losses:
                        sc = [1.0] * 10
                        sc[s - 1] = 1 - loss
                        out.append((f"loss {round(100 * loss)} %", device, rec,
                                    perturbed(rng, device, rec, scales=sc), [s], loss, seed))
                for a, b in pairs:
                    sc = [1.0] * 10
                    sc[a - 1] = sc[b - 1] = 0.9
                    out.append(("two stories 10 %", device, rec, perturbed(rng, device, rec, scales=sc),
                                [a, b], 0.1, seed))
                if device == "tmd":
                    for f in (0.9, 1.1):
                        out.append((f"TMD detuned {round(100 * (f - 1)):+d} %", device, rec,
                                    perturbed(rng, device, rec, tmd_k=TMD_K * f * f), [], 0.0, seed))
    return out


def run(args, tmp, i, case):
    label, device, rec, truth, damaged, loss, seed = case
    node = os.path.join(tmp, f"node_{i}.toml")
    tpath = os.path.join(tmp, f"truth_{i}.toml")
    with open(node, "w") as f:
        f.write(scene_text(building(device, rec)))
    with open(tpath, "w") as f:
        f.write(scene_text(truth))
    cmd = [args.vines, "hil", node, "--mode", "twin", "--truth", tpath, "--sensors", args.sensors,
           "--measure-noise-pct", str(args.noise_pct), "--seed", str(seed), "--json", "--timeout", "60"]
    if args.duration:
        cmd += ["--duration", str(args.duration)]
    cmd += args.extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    for path in (node, tpath):
        os.remove(path)
    if p.returncode not in (0, 3):
        return dict(case=case, error=p.stderr.strip() or f"exit {p.returncode}")
    r = json.loads(p.stdout)
    return dict(case=case, twin=r["twin"], steps=r["steps"], wall=r["wall_time_s"])


def pct(xs):
    return f"{100 * sum(xs) / len(xs):5.1f} %" if xs else "    -  "


def stat(xs, fmt):
    if not xs:
        return "-"
    xs = sorted(xs)
    return (fmt % statistics.fmean(xs)) + " / " + (fmt % xs[min(len(xs) - 1, int(0.9 * len(xs)))])


def table(results):
    groups = {}
    for r in results:
        if "error" in r:
            continue
        label, device = r["case"][0], r["case"][1]
        groups.setdefault((device, label), []).append(r)
    head = ("device", "truth", "runs", "detected", "located", "size err pt mean/p90", "delay s mean/p90",
            "false alarm", "roof NRMSE mean/p90", "us/step")
    rows = []
    for (device, label), rs in sorted(groups.items()):
        tw = [r["twin"] for r in rs]
        damaged = [r["case"][4] for r in rs]
        loss = [r["case"][5] for r in rs]
        det = [t["detected"] for t in tw]
        if label.startswith("TMD"):
            det = [t["device"].get("detuned", False) for t in tw]
        loc = [t["story"] in d for t, d in zip(tw, damaged)] if damaged[0] else []
        size = [100 * abs(t["size"] - l) for t, d, l in zip(tw, damaged, loss)
                if t["detected"] and t["size"] is not None and t["story"] in d and len(d) == 1]
        delay = [t["detect_delay_s"] for t in tw if t["detected"] and t["detect_delay_s"] is not None]
        nrmse = [t["roof_displacement_nrmse"] for t in tw if t["roof_displacement_nrmse"] is not None]
        us = [1e6 * r["wall"] / max(1, r["steps"]) for r in rs]
        damaged_run = bool(damaged[0]) or label.startswith("TMD")
        rows.append((device, label, str(len(rs)), pct(det) if damaged_run else "", pct(loc) if loc else "",
                     stat(size, "%.2f"), stat(delay, "%.1f"), "" if damaged_run else pct(det),
                     stat(nrmse, "%.4f"), "%.0f" % statistics.fmean(us)))
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(head)]
    line = lambda cells: "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths)) + " |"
    print(line(head))
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for r in rows:
        print(line(r))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vines", default=os.path.join(ROOT, "build", "release", "vines"))
    ap.add_argument("--records", default=os.environ.get("VINES_GROUND_MOTIONS",
                                                        os.path.join(ROOT, "..", "shared", "data", "ground_motions")))
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--undamaged", type=int, default=4, help="undamaged truths per device, record and seed")
    ap.add_argument("--duration", type=float, default=60, help="first S seconds of each record (0: all)")
    ap.add_argument("--sensors", default="3,6,8,10")
    ap.add_argument("--noise-pct", type=float, default=5)
    ap.add_argument("--quick", action="store_true", help="stories 3 and 8, 10 % only, no pairs")
    ap.add_argument("--calibrate", action="store_true", help="undamaged truths only; their largest estimates")
    ap.add_argument("--json", help="write every run's case and twin report to FILE")
    args, args.extra = ap.parse_known_args()
    if not os.access(args.vines, os.X_OK):
        fail(f"{args.vines}: not an executable (build it: cmake --preset release && cmake --build --preset release)")
    if not os.path.isdir(args.records):
        fail(f"{args.records}: no such folder of ground motions (--records, or VINES_GROUND_MOTIONS)")
    records = [os.path.join(args.records, f) for f in RECORDS if os.path.exists(os.path.join(args.records, f))]
    if not records:
        fail(f"{args.records}: none of the known records is there")
    todo = cases(args, records)
    results = []
    with tempfile.TemporaryDirectory() as tmp, cf.ThreadPoolExecutor(max(1, args.jobs)) as pool:
        futures = [pool.submit(run, args, tmp, i, c) for i, c in enumerate(todo)]
        for n, f in enumerate(cf.as_completed(futures), 1):
            results.append(f.result())
            if n % 20 == 0 or n == len(todo):
                print(f"twin_benchmark.py: {n}/{len(todo)} runs", file=sys.stderr, flush=True)
    errors = [r for r in results if "error" in r]
    for r in errors[:5]:
        print(f"twin_benchmark.py: a run failed ({r['case'][0]}, {r['case'][1]}, "
              f"{os.path.basename(r['case'][2])}): {r['error']}", file=sys.stderr)
    if args.json:
        with open(args.json, "w") as f:
            json.dump([dict(label=r["case"][0], device=r["case"][1], record=os.path.basename(r["case"][2]),
                            damaged=r["case"][4], loss=r["case"][5], seed=r["case"][6],
                            twin=r.get("twin"), error=r.get("error")) for r in results], f)
    print(f"twin benchmark: sensors {args.sensors} at 1 kHz, noise {args.noise_pct:g} % RMS, {len(records)} records, "
          f"{len(results) - len(errors)} runs ({len(errors)} failed)")
    if len(errors) == len(results):
        return 1
    table(results)
    if args.calibrate:
        worst = [max(1 - e for e in r["twin"]["eta_k"]) for r in results if "twin" in r]
        worst.sort()
        print(f"undamaged: largest final loss estimate of any story: median {statistics.median(worst):.4f}, "
              f"p99 {worst[min(len(worst) - 1, int(0.99 * len(worst)))]:.4f}, max {worst[-1]:.4f}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
