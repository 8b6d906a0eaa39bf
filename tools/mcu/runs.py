"""The runs: the plan (one scene written per target, mode, kind, record and
initial condition), one `vines hil SCENE --node qemu:TARGET --json` run on the
target's image with its figures read from the JSON report, and all of them on
a pool of workers, longest first, with progress on stderr and Ctrl-C handled."""
import concurrent.futures
import json
import os
import subprocess
import sys
import threading
import time

from . import IMAGE_OF, KINDS, PGA_G, QUICK_DURATION_S, ROOT, TARGETS, TWIN_ARGS, TWIN_KINDS, TWIN_RATE_HZ
from .images import file_hash
from .scenes import SCENE_IC, base_scene, ic_grid, records_list, vines_gap, write_scene


def plan(a, tmp, records_dir):
    """Every run: (target, mode, kind, device, record, ic, scene path, cap)."""
    kinds = ["scene"] if a.quick and not a.only else (a.only or list(KINDS))
    cap = a.duration if a.duration else (QUICK_DURATION_S if a.quick else None)
    modes = a.schemes or [None]
    recs = records_list(records_dir, a.records) if "records" in kinds else []
    gap = vines_gap(a.vines, records_dir, tmp) if "ics" in kinds else None
    jobs = []

    def add(target, mode, kind, scene, record, ic, run_cap, extra=None):
        name = f"{len(jobs):03d}_{target}_{mode or 'default'}_{kind}"
        path = os.path.join(tmp, name + ".toml")
        scene.setdefault("scene", {})["name"] = name
        write_scene(path, scene)
        job = {"target": target, "scheme": mode or "default", "kind": kind,
               "device": scene.get("device", {}).get("kind", "none"), "record": record, "ic": ic,
               "scene_file": path, "duration_cap_s": run_cap}
        job["image"] = IMAGE_OF[job["device"]]
        job.update(extra or {})
        jobs.append(job)

    for target in a.targets:
        for mode in modes:
            vs = lambda: base_scene("elcentro_vines.toml", target, records_dir, mode, a.bounded_substeps,
                                  a.split_steps)
            scene_rec = os.path.basename(vs()["record"]["path"])
            if "scene" in kinds:
                add(target, mode, "scene", vs(), scene_rec, SCENE_IC, None if a.full_scene else cap)
            for rec in recs:
                sc = vs()
                sc["record"] = {"path": os.path.join(records_dir, rec), "format": "auto", "pga_g": PGA_G}
                add(target, mode, "records", sc, f"{rec} @{PGA_G} g", SCENE_IC, cap)
            for label, u, v in (ic_grid(gap) if gap is not None else []):
                sc = vs()
                sc.setdefault("vines", {}).update({"initial_position_m": u, "initial_velocity_mps": v})
                add(target, mode, "ics", sc, scene_rec, label, cap,
                    {"initial_position_m": u, "initial_velocity_mps": v, "gap_m": gap})
        for kind, name in (("tmd", "elcentro_tmd.toml"), ("bare", "elcentro_bare.toml")):
            if kind in kinds:
                sc = base_scene(name, target, records_dir)
                add(target, None, kind, sc, os.path.basename(sc["record"]["path"]), "at rest", cap)
        for kind, (_, name) in TWIN_KINDS.items():
            if kind in kinds and TARGETS[target][1] != "fixed":  # no twin image in fixed point
                sc = base_scene(name, target, records_dir)
                sc["loop"]["sensor_rate_hz"] = sc["output"]["rate_hz"] = TWIN_RATE_HZ
                add(target, None, kind, sc, os.path.basename(sc["record"]["path"]), "at rest", cap,
                    {"hil_args": TWIN_ARGS, "image": "twin"})
    return jobs


# The board image of a run: its preset's build of the run's device's image (or the twin's).
def image_for(job):
    return os.path.join(ROOT, "build", job["target"], "firmware", "app", f"vines_node_{job['image']}.elf")


# One `vines hil` run of the board in QEMU: the figures of its JSON report, or its error;
# odd lists anything unexpected.
def run_one(vines, job):
    cmd = [vines, "hil", job["scene_file"], "--node", "qemu:" + job["target"], "--json",
           "--image", image_for(job)]
    if job["duration_cap_s"]:
        cmd += ["--duration", repr(float(job["duration_cap_s"]))]
    cmd += job.get("hil_args", [])
    before = file_hash(image_for(job))
    t0 = time.monotonic()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        return {"error": f"{vines}: {e.strerror}"}
    wall = time.monotonic() - t0
    res = {"command": " ".join(cmd), "tool_wall_time_s": round(wall, 1), "image_sha256": before}
    if file_hash(image_for(job)) != before:
        res["image_rebuilt_during_run"] = True
    if r.returncode != 0:
        msg = r.stderr.strip() or r.stdout.strip() or f"exit status {r.returncode}"
        res["error"] = msg
        return res
    try:
        j = json.loads(r.stdout)
    except ValueError:
        res["error"] = "vines hil printed no JSON report: " + r.stdout[-300:] + r.stderr[-300:]
        return res
    nd = j.get("node_deadline", {})
    if "worst_step_instructions" not in j:
        res["error"] = "no worst_step_instructions in the report (not a board node?)"
        return res
    res.update({
        "steps": j.get("steps"), "samples": j.get("samples"),
        "worst": j["worst_step_instructions"], "worst_k": j.get("worst_step_k"),
        "median": j.get("median_step_instructions"),
        "overruns": nd.get("overruns"), "budget_ticks": nd.get("budget_ticks"),
        "stack_peak_bytes": nd.get("stack_peak_bytes"), "step_ticks": j.get("step_ticks"),
        "max_deviation_from_offline": j.get("max_deviation_from_offline"),
        "outputs_finite": j.get("outputs_finite"), "missing_steps": j.get("missing_steps"),
        "node_exit_status": j.get("node_status", {}).get("exit_status"),
        "wall_time_s": j.get("wall_time_s"),
    })
    odd = []
    if res.get("image_rebuilt_during_run"):
        odd.append("the image changed during the run")
    if j.get("outputs_finite") is False:
        odd.append("non-finite output")
    if j.get("steps") != j.get("samples"):
        odd.append(f"{j.get('steps')} steps for {j.get('samples')} samples")
    if j.get("missing_steps"):
        odd.append(f"{j['missing_steps']} missing steps")
    if res["node_exit_status"] not in (0, None):
        odd.append(f"node exit status {res['node_exit_status']}")
    if res["worst_k"] == 0:
        odd.append("the worst step is the init (k 0)")
    if odd:
        res["odd"] = odd
    return res


# Every run, `workers` at once, progress on stderr. False if interrupted: the runs not
# finished get an error.
def run_all(vines, jobs, workers):
    # Longest first (samples to stream), for the pool's makespan.
    def est(job):
        return TARGETS[job["target"]][2] * (job["duration_cap_s"] or 60.0)
    order = sorted(range(len(jobs)), key=lambda i: -est(jobs[i]))
    lock, done = threading.Lock(), [0]
    t_start = time.monotonic()

    def work(i):
        job = jobs[i]
        res = run_one(vines, job)
        job.update(res)
        with lock:
            done[0] += 1
            what = f"{job['target']} {job['scheme']} {job['kind']} {job['record']} {job['ic']}"
            if "error" in res:
                first = res["error"].splitlines()[-1] if res["error"] else ""
                line = f"FAILED: {first}"
            else:
                line = (f"worst {res['worst']:.0f} (k {res['worst_k']}), median {res['median']:.0f}, "
                        f"{res['steps']} steps, {res['tool_wall_time_s']:.0f} s"
                        + (f"; {'; '.join(res['odd'])}" if res.get("odd") else ""))
            print(f"[{done[0]}/{len(jobs)} {time.monotonic() - t_start:6.0f} s] {what}: {line}",
                  file=sys.stderr, flush=True)

    pool = concurrent.futures.ThreadPoolExecutor(max_workers=workers)
    futures = [pool.submit(work, i) for i in order]
    try:
        for f in futures:
            f.result()
    except KeyboardInterrupt:
        # Report what finished: the runs under way end with their vines (which
        # got the same SIGINT from the terminal), the others are not started.
        print("mcu_report: interrupted; waiting for the runs under way, then reporting the finished ones",
              file=sys.stderr, flush=True)
        pool.shutdown(wait=True, cancel_futures=True)
        for job in jobs:
            if "worst" not in job and "error" not in job:
                job["error"] = "not run (interrupted)"
        return False
    pool.shutdown()
    return True
