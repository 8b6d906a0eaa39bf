"""The report: per target, the figures of each mode's VI NES runs and of the
TMD and bare-frame runs (worst and median step, sustained rate, flash, RAM,
stack), the images and every run, as the JSON object of --json or as text."""
import re

from . import IMAGE_OF, IMAGES, MARGIN, QUICK_DURATION_S, TARGETS, TWIN_KINDS


# The figures of one group of runs on one image (a mode's VI NES runs, or the TMD or
# bare-frame runs); the same error from several runs once, with a count.
def figures(runs, image, clock, reference_kind):
    ok = [r for r in runs if "error" not in r]
    errors = {}
    for r in runs:
        if "error" in r:  # the same refusal from every scene of a mode: once, with a count
            e = re.sub(re.escape(r["scene_file"]) + r"(:\d+)?", "<scene>", r["error"])
            errors[e] = errors.get(e, 0) + 1
    out = {"runs_ok": len(ok), "runs_failed": len(runs) - len(ok),
           "errors": [f"({n} run{'s' if n > 1 else ''}) {e}" for e, n in sorted(errors.items())]}
    out.update({k: image[k] for k in ("flash_bytes", "ram_bytes", "ram_bytes_with_guard", "ram_static_bytes")})
    out["stack_bytes_call_graph"] = image["stack_bytes_call_graph"]
    if not ok:
        return out
    w = max(ok, key=lambda r: r["worst"])
    ref = [r for r in ok if r["kind"] == reference_kind] or ok
    medians = [r["median"] for r in ok]
    out.update({
        "instructions_per_step_max": w["worst"],
        "worst_run": {k: w.get(k) for k in ("kind", "record", "ic", "worst_k", "duration_cap_s")},
        "instructions_per_step_median": ref[0]["median"],
        "median_of_run": {k: ref[0].get(k) for k in ("kind", "record", "ic", "duration_cap_s")},
        "run_medians_min": min(medians), "run_medians_max": max(medians),
        "stack_bytes_max": max(r["stack_peak_bytes"] or 0 for r in ok),
        "steps_total": sum(r["steps"] or 0 for r in ok),
        "overruns_total": sum(r["overruns"] or 0 for r in ok),
        "max_sensor_rate_hz": clock / (MARGIN * w["worst"]),
        "all_outputs_finite": all(r.get("outputs_finite") is True for r in ok),
    })
    return out


# One target's report (the JSON object of --json): figures per mode, TMD and bare frame,
# the images and every run.
def report(target, jobs, images, a):
    board, scalar, rate, clock = TARGETS[target]
    runs = [j for j in jobs if j["target"] == target]
    modes = {}
    for mode in (a.schemes or ["default"]):
        mine = [r for r in runs if r["device"] == "vines" and r["scheme"] == mode and r["kind"] not in TWIN_KINDS]
        if mine:
            modes[mode] = figures(mine, images[(target, IMAGE_OF["vines"])], clock, "scene")
    rep = {"target": target, "board": board, "scalar": scalar, "sensor_rate_hz": rate, "clock_hz": clock,
           "margin": MARGIN, "instructions_per_cycle_assumed": 1,
           "duration_cap_s": a.duration if a.duration else (QUICK_DURATION_S if a.quick else None),
           "full_scene": a.full_scene,
           "images": {d: images[(target, d)] for d in IMAGES if (target, d) in images},
           "modes": modes}
    for kind, dev in (("tmd", "tmd"), ("bare", "none")) + tuple((k, "twin") for k in TWIN_KINDS):
        mine = [r for r in runs if r["kind"] == kind]
        if mine:
            rep[kind] = figures(mine, images[(target, IMAGE_OF.get(dev, dev))], clock, kind)
    keep = ("kind", "device", "image", "scheme", "record", "ic", "initial_position_m", "initial_velocity_mps",
            "duration_cap_s", "steps", "samples", "worst", "worst_k", "median", "overruns", "stack_peak_bytes",
            "max_deviation_from_offline", "outputs_finite", "wall_time_s", "tool_wall_time_s", "odd", "error")
    rep["runs"] = [{k: r[k] for k in keep if k in r} for r in runs]
    for r, out in zip(runs, rep["runs"]):
        # A build during the report: the run's image is not the one sized.
        sized = images[(target, r["image"])]["sha256"]
        if r.get("image_sha256") and r["image_sha256"] != sized:
            out["image_sha256"] = r["image_sha256"]
            out.setdefault("odd", []).append(f"image {r['image_sha256']}, not the one sized ({sized})")
    return rep


# The text lines of one group's figures.
def fmt_block(name, f, clock):
    lines = [f"  {name}: {f['runs_ok']} runs ok, {f['runs_failed']} failed"]
    for e in f["errors"]:
        lines.append("    error: " + e.replace("\n", "\n           "))
    if "instructions_per_step_max" not in f:
        return lines
    w = f["worst_run"]
    lines += [
        f"    worst step      {f['instructions_per_step_max']:9.0f} instructions  "
        f"({w['kind']}: {w['record']}, {w['ic']}, k {w['worst_k']})",
        f"    median step     {f['instructions_per_step_median']:9.0f} instructions  "
        f"({f['median_of_run']['kind']} run; runs' medians {f['run_medians_min']:.0f}-{f['run_medians_max']:.0f})",
        f"    sustained rate  {f['max_sensor_rate_hz']:9.0f} Hz at {clock / 1e6:.0f} MHz "
        f"(1 instruction/cycle assumed, {MARGIN:g}x margin on the worst step)",
        f"    flash {f['flash_bytes']} B; RAM {f['ram_bytes']} B (static {f['ram_static_bytes']} B + stacks; "
        f"{f['ram_bytes_with_guard']} B with the MPU guard)",
        f"    stack           {f['stack_bytes_max']:9d} B painted (max over runs), "
        f"{f['stack_bytes_call_graph']} B call-graph bound",
        f"    {f['steps_total']} steps, {f['overruns_total']} over one sensor period (QEMU's clock); "
        f"outputs finite: {f['all_outputs_finite']}",
    ]
    return lines


# One target's report as text (without --json).
def print_text(rep):
    cap = rep["duration_cap_s"]
    print(f"{rep['target']} ({rep['board']}, {rep['scalar']}, {rep['sensor_rate_hz']:g} Hz"
          + (f", runs capped at {cap:g} s" + (" except the scene run" if rep["full_scene"] else "") if cap else "")
          + ")")
    for mode, f in rep["modes"].items():
        print("\n".join(fmt_block(f"VI NES, mode {mode}", f, rep["clock_hz"])))
    for kind, label in (("tmd", "TMD"), ("bare", "bare frame"), ("twin_vines", "twin node, VI NES building"),
                        ("twin_tmd", "twin node, TMD building"), ("twin_bare", "twin node, bare frame")):
        if kind in rep:
            print("\n".join(fmt_block(label, rep[kind], rep["clock_hz"])))
    for d, im in rep["images"].items():
        extra = []
        if im["call_graph_dynamic_frames"]:
            extra.append(f"{len(im['call_graph_dynamic_frames'])} dynamic frames")
        if im["call_graph_unanalysed_callees"]:
            u = im["call_graph_unanalysed_callees"]
            extra.append("not followed: " + ", ".join(u[:6]) + (" ..." if len(u) > 6 else ""))
        print(f"  image {d}: flash {im['flash_bytes']} B, .data {im['data_bytes']} + .bss {im['bss_bytes']} B, "
              f".stack {im['stack_section_bytes']} B (guard {im['stack_guard_bytes']}, process "
              f"{im['process_stack_bytes']}, handler {im['handler_stack_bytes']}); call graph "
              f"{im['stack_bytes_call_graph']} B" + (f" ({'; '.join(extra)})" if extra else ""))
    print("  runs:")
    print(f"    {'kind':7s} {'scheme':9s} {'record':52s} {'initial condition':24s} {'steps':>7s} "
          f"{'worst':>8s} {'k':>7s} {'median':>7s} {'over':>5s} {'stack':>6s} {'wall s':>7s}")
    for r in rep["runs"]:
        head = f"    {r['kind']:7s} {r['scheme']:9s} {r['record'][:52]:52s} {r['ic']:24s} "
        if "error" in r:
            print(head + "FAILED: " + r["error"].splitlines()[-1])
            continue
        print(head + f"{r['steps']:7d} {r['worst']:8.0f} {r['worst_k']:7d} {r['median']:7.0f} "
              f"{r['overruns']:5d} {r['stack_peak_bytes']:6d} {r['tool_wall_time_s']:7.0f}"
              + (f"  ({'; '.join(r['odd'])})" if r.get("odd") else ""))
