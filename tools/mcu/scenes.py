"""The runs' scenes: the shipped scenes of data/scenes read with tomllib and
set to the target's rate and scalar (and contact scheme), written back as TOML;
the record paths resolved, the ground-motion files listed, the VI NES gap read
from `vines run`'s summary and the grid of initial conditions built on it."""
import fnmatch
import json
import math
import os
import subprocess

from . import SCENES, TARGETS, Failure


# A TOML file read with tomllib; unreadable or malformed, a Failure naming it.
def load_toml(path):
    try:
        import tomllib
    except ImportError:
        raise Failure("Python 3.11 or later is needed (tomllib)")
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except OSError as e:
        raise Failure(f"{path}: {e.strerror}")
    except tomllib.TOMLDecodeError as e:
        raise Failure(f"{path}: {e}")


# One value of a scene in TOML syntax (booleans, numbers, strings, lists of them).
def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise Failure(f"cannot write {v} in a scene")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise Failure(f"cannot write {v!r} in a scene")


# A scene ({table: {key: value}}) written as a TOML file, one table after another.
def write_scene(path, scene):
    lines = []
    for table, keys in scene.items():
        lines.append(f"[{table}]")
        lines.extend(f"{k} = {toml_value(v)}" for k, v in keys.items())
        lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines))


# A scene's record path made absolute: beside the scenes, else in the ground-motion
# folder; else left as written.
def resolve_record(path, records_dir):
    if os.path.isabs(path):
        return path
    for base in (SCENES, records_dir):
        p = os.path.join(base, path)
        if os.path.isfile(p):
            return p
    return path  # left to vines' own search (and its error)


def base_scene(name, target, records_dir, scheme=None, bounded_substeps=None, split_steps=None):
    """A shipped scene at the target's rate and scalar, output trimmed."""
    _, scalar, rate, _ = TARGETS[target]
    sc = load_toml(os.path.join(SCENES, name))
    sc = {t: dict(v) for t, v in sc.items()}
    sc.setdefault("record", {})["path"] = resolve_record(sc["record"].get("path", ""), records_dir)
    loop = sc.setdefault("loop", {})
    loop["sensor_rate_hz"] = rate
    loop["scalar"] = scalar  # the board's scalar wins anyway
    if scheme is not None:
        loop["contact_scheme"] = scheme
        if scheme == "bounded" and bounded_substeps is not None:
            loop["bounded_substeps"] = bounded_substeps
    if split_steps is not None and (scheme == "split" or (scheme is None and scalar == "fixed")):
        loop["split_steps"] = split_steps
    if scalar == "fixed":
        fixed_point(loop, scheme)
    sc["output"] = {"rate_hz": rate, "timeseries": False}
    return sc


# A fixed-point board's loop (docs/fixed_point.md): the split scheme at 16
# steps a contact (the real-time setting), no ledger, units for the
# workload's ground accelerations (El Centro's PGA 3.42 m/s^2, the records
# at 0.35 g).
FIXED_ACCEL_MPS2 = 3.5
FIXED_SPLIT_STEPS = 16


def fixed_point(loop, scheme):
    if scheme is None:
        loop["contact_scheme"] = "split"
    loop.setdefault("split_steps", FIXED_SPLIT_STEPS)
    loop["energy_ledger"] = False
    loop["fixed_accel_mps2"] = FIXED_ACCEL_MPS2


def vines_gap(vines, records_dir, tmp):
    """The VI NES free travel (m) of the shipped scene, from `vines run`'s summary."""
    sc = base_scene("elcentro_vines.toml", "cortex-m7", records_dir)
    sc["record"]["duration_s"] = 0.01
    path = os.path.join(tmp, "gap.toml")
    write_scene(path, sc)
    out = os.path.join(tmp, "gap_run")
    r = subprocess.run([vines, "run", path, "--out", out], capture_output=True, text=True)
    if r.returncode != 0:
        raise Failure(f"{vines} run {path} (for the gap):\n{r.stderr.strip()}")
    try:
        with open(os.path.join(out, "summary.json")) as f:
            return float(json.load(f)["device_params"]["gap_m"])
    except (OSError, KeyError, TypeError, ValueError) as e:
        raise Failure(f"no device_params.gap_m in {out}/summary.json ({e})")


def ic_grid(gap):
    """(label, position, velocity); u = -gap at rest is the scene run."""
    return [("u=-gap/2 v=0", -gap / 2, 0.0), ("u=0 v=0", 0.0, 0.0), ("u=+gap/2 v=0", gap / 2, 0.0),
            ("u=0 v=+0.5", 0.0, 0.5), ("u=0 v=-1.0", 0.0, -1.0)]


# The initial condition of the shipped scene, as the runs name it.
SCENE_IC = "u=-gap v=0 (left wall)"


# The record files of the ground-motion folder to run, --records globs applied.
def records_list(records_dir, pattern):
    if not os.path.isdir(records_dir):
        raise Failure(f"{records_dir}: no ground-motion folder (--records-dir, or $VINES_GROUND_MOTIONS)")
    names = sorted(n for n in os.listdir(records_dir)
                   if os.path.isfile(os.path.join(records_dir, n)) and n != "SOURCES.md")
    if pattern:
        globs = pattern.split(",")
        names = [n for n in names if any(fnmatch.fnmatch(n, g) for g in globs)]
        if not names:
            raise Failure(f"--records {pattern}: no file of {records_dir} matches")
    return names
