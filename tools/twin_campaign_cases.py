"""The twin campaign's runs (tools/twin_benchmark.py): records, scenes and the sampled design.

Records are read as `vines run` reads them (the vines Python package when it is built, else the
reader below, which follows hal/host/record.cpp for the formats of RECORDS); each run's duration
is max(40 s, the record's 95 % Arias time + 10 s), the Arias intensity taken over the whole
record, and no longer than the record. The design draws every truth and every assignment of a
story and a loss to a record and a noise seed from one seed: the same seed, the same campaign.
"""
import math
import os
import random
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TABLE1_MASS_T = [179, 170, 161, 152, 143, 134, 125, 116, 107, 98]
TABLE1_K_MN = [62.47, 52.26, 56.14, 53.02, 49.91, 46.79, 43.67, 40.55, 37.43, 34.31]
TMD_K, TMD_C = 488732.6137915217, 44133.36142032142  # the Den Hartog design of elcentro_tmd.toml
GAP_M = 0.4148  # the VI NES sphere's free travel each side of the box centre (elcentro_vines.toml)
SPHERE_T = 55.794  # the VI NES sphere's mass (data/scenes/twin/truth_sphere_stuck.toml)
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
G = 9.80665
DEVICES = ("none", "tmd", "vines")
LOSSES = (0.03, 0.05, 0.10, 0.20)
HEALTHY_K_PCT, MASS_PCT, EPS_PCT = 3.0, 2.0, 2.0
MIN_DURATION_S, AFTER_A95_S = 40.0, 10.0


def is_sct(record):
    """Mexico City SCT: its strong motion lies after 40 s; the table gives it lines of its own."""
    return "_SCT_" in os.path.basename(record)


# ---- records ----

def _numbers(line):
    return [float(t.replace("D", "E").replace("d", "e")) for t in line.split()]


def read_record_plain(path, format, units="g", column=1):
    """(samples in m/s^2, dt) of a record file: PEER AT2 (NPTS and DT on a header line, units
    from the header) or time/acceleration columns (dt from the time column's end points)."""
    with open(path) as f:
        lines = f.read().splitlines()
    if format == "at2":
        for i, line in enumerate(lines[:10]):
            n, dt = re.search(r"\bNPTS\s*=\s*(\d+)", line, re.I), re.search(r"\bDT\s*=\s*([0-9.eEdD+-]+)", line, re.I)
            if n and dt:
                break
        else:
            raise ValueError(f"{path}: no 'NPTS= .., DT= ..' header line in the first 10 lines")
        head = " ".join(lines[:i + 1]).lower()
        scale = G if re.search(r"units\s+(of\s+)?g\b|\(g\)", head) else 1.0 if "m/s" in head else 0.01 if (
            "cm/s" in head or "gal" in head) else G
        acc = [v for line in lines[i + 1:] for v in _numbers(line)]
        if len(acc) != int(n.group(1)):
            raise ValueError(f"{path}: NPTS={n.group(1)} in the header but {len(acc)} values read")
        return [scale * a for a in acc], float(dt.group(1))
    rows = [_numbers(line.split("#")[0]) for line in lines if line.split("#")[0].strip()]
    dt = (rows[-1][0] - rows[0][0]) / (len(rows) - 1)
    scale = {"g": G, "m/s2": 1.0, "cm/s2": 0.01}[units]
    return [scale * r[column] for r in rows], dt


def _vines_package(vines_exe):
    """The vines Python package beside the program (its build's python/), else on sys.path."""
    for d in (os.path.join(os.path.dirname(os.path.abspath(vines_exe)), "python") if vines_exe else None,
              os.path.join(ROOT, "build", "release", "python")):
        if d and os.path.isdir(os.path.join(d, "vines")) and d not in sys.path:
            sys.path.insert(0, d)
    try:
        import vines
        return vines
    except ImportError:
        return None


def read_record(path, vines_exe=None):
    """(samples in m/s^2, dt): vines.Record.load when the package is built, else read_record_plain."""
    keys = RECORDS[os.path.basename(path)]
    pkg = _vines_package(vines_exe)
    if pkg is not None:
        rec = pkg.Record.load(path, **keys)
        return list(rec.acc), rec.dt
    return read_record_plain(path, **keys)


def arias_times(acc, dt, shares=(0.05, 0.25, 0.75, 0.95)):
    """The times [s from the first sample] at which the running sum of a^2 first reaches each
    share of the whole record's (as hil/modes/twin.cpp dates the 5 % time)."""
    total = math.fsum(a * a for a in acc)
    out, run, k = [], 0.0, 0
    for share in shares:
        while k < len(acc) and run + acc[k] * acc[k] < share * total:
            run += acc[k] * acc[k]
            k += 1
        out.append(k * dt)
    return out


def record_info(path, vines_exe=None):
    """What the design needs of a record: its length, Arias 5/25/75/95 % times, the run's duration."""
    acc, dt = read_record(path, vines_exe)
    t05, t25, t75, t95 = arias_times(acc, dt)
    length = dt * (len(acc) - 1)
    return dict(path=path, name=os.path.basename(path), length_s=length, t05=t05, t25=t25, t75=t75, t95=t95,
                duration_s=run_duration(t95, length), sct=is_sct(path))


def run_duration(t95, length_s):
    """max(40 s, Arias 95 % + 10 s), the record's length at most (the program stops there)."""
    return min(max(MIN_DURATION_S, t95 + AFTER_A95_S), length_s)


# ---- scenes ----

def building(device, record, *, masses=None, scales=None, eps=0.7, x0=0.0, tmd_k=None, tmd_x0=0.0,
             damage=None, stuck=False):
    """A scene's tables: the Table 1 frame (masses, per-story scales), a device, a record; damage
    = (time_s, per-story factors) adds the [damage] table; stuck: the sphere jammed in its box
    (no device, its mass on the top floor, as data/scenes/twin/truth_sphere_stuck.toml)."""
    frame = {"preset": "table1"}
    if masses or stuck:
        m = list(masses or TABLE1_MASS_T)
        if stuck:
            m[-1] += SPHERE_T
        frame = {"preset": "custom", "masses_kg": [x * 1e3 for x in m],
                 "stiffnesses_n_per_m": [k * 1e6 for k in TABLE1_K_MN], "damping": "stiffness",
                 "stiffness_damping_s": 0.0129}
    if scales:
        frame["stiffness_scales"] = scales
    kind = "none" if stuck else device
    t = {"scene": {"name": "twin_bench"}, "frame": frame, "device": {"kind": kind}}
    if kind != "none":
        t["device"]["mass_ratio"] = 0.05
    if kind == "vines":
        t["vines"] = {"law": "kuwabara", "beta": 1.35, "eps": eps, "v_ref_mps": 0.5, "initial_position_m": x0}
    if kind == "tmd":
        t["tmd"] = {"initial_position_m": tmd_x0}
        if tmd_k:
            t["tmd"].update({"k_n_per_m": tmd_k, "c_ns_per_m": TMD_C})
    t["record"] = dict({"path": record}, **RECORDS[os.path.basename(record)])
    t["loop"] = {"sensor_rate_hz": 1000.0}
    if damage:
        t["damage"] = {"time_s": damage[0], "stiffness_scales": damage[1]}
    return t


def healthy_truth(rng):
    """The building as built: each story's stiffness within 3 %, each floor's mass within 2 %, eps
    within 2 % of the node's scene; the sphere anywhere in 80 % of its travel, the TMD within 5 cm."""
    return dict(scales=[1 + HEALTHY_K_PCT / 100 * rng.uniform(-1, 1) for _ in range(10)],
                masses=[m * (1 + MASS_PCT / 100 * rng.uniform(-1, 1)) for m in TABLE1_MASS_T],
                eps=0.7 * (1 + EPS_PCT / 100 * rng.uniform(-1, 1)),
                x0=0.8 * GAP_M * rng.uniform(-1, 1), tmd_x0=0.05 * rng.uniform(-1, 1))


# ---- the design ----

def plan(quick):
    """How many runs of each family: undamaged per device and record; single losses during the
    record per device, story and loss (0: each story and loss once over the three devices); pairs
    of stories per device; losses before the record per device, story and loss; detuned TMDs per
    frequency; stuck spheres per record."""
    if quick:
        return dict(undamaged=3, replicates=0, pairs=1, before=(0.10,), before_stories=(3, 8), before_reps=1,
                    detuned=1, stuck=1)
    return dict(undamaged=15, replicates=10, pairs=20, before=(0.05, 0.10), before_stories=tuple(range(1, 11)),
                before_reps=2, detuned=5, stuck=2)


def _slots(rng, records, seeds):
    """An endless round of (record, noise seed), each record once per round, shuffled per round."""
    k = 0
    while True:
        order = list(records)
        rng.shuffle(order)
        for rec in order:
            yield rec, 1 + k % seeds
            k += 1


def cases(records, *, quick=False, seed=20261125, seeds=5, calibrate=False, undamaged=None, replicates=None,
          families=None):
    """Every run: dicts with family, label, device, record, truth (scene tables), damaged stories,
    loss, onset_s (the truth's damage time; None before the record or undamaged), healthy
    factors, masses, seed (noise), duration_s. records: record_info() dicts."""
    p = plan(quick)
    if undamaged is not None:
        p["undamaged"] = undamaged
    if replicates is not None:
        p["replicates"] = replicates
    rng = random.Random(seed)
    out = []

    def add(family, label, device, rec, noise_seed, damaged=(), loss=0.0, onset=None, before=False, **kw):
        h = healthy_truth(rng)
        scales, damage = list(h["scales"]), None
        factors = [1.0] * 10
        for s in damaged:
            factors[s - 1] = 1 - loss
        if damaged and before:
            scales = [a * b for a, b in zip(scales, factors)]
        elif damaged:
            damage = (round(onset, 3), factors)
        truth = building(device, rec["path"], masses=h["masses"], scales=scales, eps=h["eps"], x0=h["x0"],
                         tmd_x0=h["tmd_x0"], damage=damage, **kw)
        out.append(dict(family=family, label=label, device=device, record=rec["path"], sct=rec["sct"],
                        truth=truth, damaged=list(damaged), loss=loss, onset_s=damage[0] if damage else None,
                        healthy=h["scales"], masses=h["masses"], seed=noise_seed, duration_s=rec["duration_s"]))

    def onset(rec):
        return rng.uniform(rec["t25"], rec["t75"])

    for device in DEVICES:
        slot = _slots(rng, records, seeds)
        for rec in records:
            for j in range(p["undamaged"]):
                add("undamaged", "undamaged", device, rec, 1 + j % seeds)
        if calibrate:
            continue
        # Single losses during the record: every story and loss, `replicates` times per device
        # (quick: once over the three devices), each on the next record of a shuffled round.
        grid = [(s, loss) for s in range(1, 11) for loss in LOSSES]
        if p["replicates"]:
            grid = grid * p["replicates"]
        else:
            grid = [c for i, c in enumerate(grid) if i % len(DEVICES) == DEVICES.index(device)]
        for s, loss in grid:
            rec, ns = next(slot)
            add("during", f"loss {round(100 * loss)} % during", device, rec, ns, [s], loss, onset(rec))
        for _ in range(p["pairs"]):
            rec, ns = next(slot)
            a, b = sorted(rng.sample(range(1, 11), 2))
            add("two during", "two stories 10 % during", device, rec, ns, [a, b], 0.10, onset(rec))
        for loss in p["before"]:
            for s in [s for s in p["before_stories"] for _ in range(p["before_reps"])]:
                rec, ns = next(slot)
                add("before", f"loss {round(100 * loss)} % before, no baseline", device, rec, ns, [s], loss,
                    before=True)
        if device == "tmd":
            for f in (0.9, 1.1):
                for _ in range(p["detuned"]):
                    rec, ns = next(slot)
                    add("detuned", f"TMD detuned {round(100 * (f - 1)):+d} %", device, rec, ns, tmd_k=TMD_K * f * f)
        if device == "vines":
            for _ in range(p["stuck"] * len(records)):
                rec, ns = next(slot)
                add("stuck", "sphere stuck", device, rec, ns, stuck=True)
    if families:
        out = [c for c in out if c["family"] in families]
    return out
