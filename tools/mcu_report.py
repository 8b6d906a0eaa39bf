#!/usr/bin/python3
"""Cost of the firmware's link node on each MCU target, measured in QEMU:
instructions per step (worst, median) over a workload of records and initial
conditions, per contact scheme; flash and RAM (arm-none-eabi-size); stack
(painted high-water mark from the runs, and the call-graph bound of
-fcallgraph-info=su); the highest sensor rate the worst step sustains.

  tools/mcu_report.py [--vines PATH] [--targets cortex-m4f,cortex-m7,cortex-m3]
                      [--schemes adaptive,bounded,split [--bounded-substeps N]
                      [--split-steps N]]
                      [--quick] [--duration S] [--full-scene] [--records GLOB]
                      [--only scene,records,ics,tmd,bare,twin_vines,twin_tmd,twin_bare]
                      [--keep-scenes DIR]
                      [-j N] [--json]

Each run is `VINES hil SCENE --node qemu:TARGET --json --image ELF
[--duration S]` (VINES: --vines, default build/release/vines) on a scene written
to a temporary folder (--keep-scenes DIR: to DIR, kept). Per target (cortex-m4f: float, 1000 Hz sensor rate,
168 MHz for the rate figure; cortex-m7: double, 2048 Hz, 480 MHz; cortex-m3, not
in the default list: Q3.28 fixed point, 1000 Hz, 120 MHz, the scenes in fixed
point: the split scheme at split_steps 16 unless --schemes, no energy ledger,
units for 3.5 m/s^2, no twin runs) and per mode (contact scheme), the VI NES
runs are:
  scene    data/scenes/elcentro_vines.toml as shipped (El Centro 2688-point,
           0.3487 g, particle at rest against the left wall: u = -gap), at
           the target's rate;
  records  every file of the ground-motion folder (SOURCES.md skipped;
           --records GLOB keeps the matching names) on the same scene,
           rescaled to a PGA of 0.35 g (record.pga_g; format "auto", so a
           multi-column file gives its first column after time);
  ics      El Centro as in the scene, particle at u = -gap/2, 0, +gap/2 at
           rest and u = 0 with v = +0.5 and -1.0 m/s (u = -gap at rest is the
           scene run; gap read from `VINES run`'s summary of the scene);
and once per target, not per mode: the TMD scene (elcentro_tmd.toml) and the
bare frame (elcentro_bare.toml) at the target's rate. The twin node (docs/twin.md;
kinds twin_vines, twin_tmd, twin_bare): the twin image with the estimator,
each device's building, El Centro at 1 kHz, floors 3, 6, 8, 10 measured with
5 % noise (vines hil --mode twin --sensors 3,6,8,10 --measure-noise-pct 5). --only limits the
kinds. --quick: the scene only, 3 s (or --duration). --duration S caps every
run (vines hil --duration), except the scene run with --full-scene.
Modes: without --schemes one mode, "default": no contact_scheme key is
written and the build's own scheme runs. With --schemes each listed scheme
is a mode: [loop] contact_scheme = "NAME" is written in the VI NES scenes
(and bounded_substeps = N for "bounded" when --bounded-substeps is given);
a build that refuses the key reports that mode's runs as failed, with
vines' message. --split-steps N writes [loop] split_steps = N for the split
scheme (and the fixed-point board's, whose default is 16; the scene's
default is 64).

Figures, per target and mode (VI NES image, that mode's runs):
  instructions_per_step_max     max over runs of worst_step_instructions (the
                                node's deadline monitor, 25 MHz ticks x 5:
                                QEMU -icount shift=3); its run's record,
                                initial condition and step k beside it (k 0
                                is the model's init on the first sample)
  instructions_per_step_median  median step of the scene run (the El Centro
                                reference workload); the range of the runs'
                                medians beside it
  flash_bytes   .isr_vector .text .ARM.extab .ARM.exidx .preinit_array
                .init_array and .data's load image
  ram_bytes     .data + .bss + .stack - __stack_guard_size: .stack
                (sections.ld) is the 32 KiB no-access MPU guard at the
                bottom of RAM, the process stack (__stack_size) and the
                handler stack (__handler_stack_size); the guard holds no data
                and is not counted (ram_bytes_with_guard includes it)
  stack_bytes_max         painted high-water mark of the process stack
                          (node_deadline.stack_peak_bytes), max over runs
  stack_bytes_call_graph  worst path from vines_start through the .ci files
                          (indirect calls, library code without call-graph
                          info and alloca frames are not in it: listed)
  max_sensor_rate_hz      clock / (1.5 x instructions_per_step_max), assuming
                          1 instruction per cycle (QEMU counts instructions,
                          not cycles: no pipeline, cache or memory timing)
The TMD and bare-frame runs get the same figures under "tmd" and "bare".

--json prints one JSON object per target, one per line: target, board,
scalar, sensor_rate_hz, clock_hz, margin, duration_cap_s, images (per device:
ELF, sizes, call-graph bound), modes (per mode: the figures above, worst_run,
runs_ok, runs_failed, errors), tmd, bare, and runs (every run: kind, device,
scheme, record, ic, duration_cap_s, steps, samples, worst, worst_k, median,
overruns, stack_peak_bytes, max_deviation_from_offline, outputs_finite,
wall_time_s, error; odd: anything unexpected, e.g. the image rebuilt
during the report, so that the run's image is not the one sized). Progress
goes to stderr.

Exit status 0 if every run succeeded, 1 if a run failed (the others are
still reported) or on a user error (missing vines or image: says what to
build). Interrupted (Ctrl-C), it waits for the runs under way and reports
the finished ones (status 130). Needs: the presets cortex-m4f / cortex-m7 built (images
build/TARGET/firmware/app/vines_node_{none,tmd,kuwabara,twin}.elf), a host build of
vines, qemu-system-arm, arm-none-eabi-size and -nm. Standard library only.
"""
import argparse
import contextlib
import io
import json
import math
import os
import shutil
import sys
import tempfile

# The package mcu/ beside this script, from any working folder.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figures  # noqa: E402
from mcu import KINDS, ROOT, TARGETS, Failure  # noqa: E402
from mcu.images import image_info  # noqa: E402
from mcu.report import print_text, report  # noqa: E402
from mcu.runs import image_for, plan, run_all  # noqa: E402


# The options checked, the scenes written, the images sized, the runs run and reported;
# returns the exit status.
def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--vines", default=os.path.join("build", "release", "vines"),
                    help="the host build's vines (default build/release/vines)")
    ap.add_argument("--targets", default="cortex-m4f,cortex-m7")
    ap.add_argument("--schemes", help="contact schemes, one mode each (e.g. adaptive,bounded); "
                                      "default: the build's own, no key written")
    ap.add_argument("--bounded-substeps", type=int, help="[loop] bounded_substeps for the bounded scheme")
    ap.add_argument("--split-steps", type=int, help="[loop] split_steps for the split scheme")
    ap.add_argument("--quick", action="store_true", help="El Centro scene only, 3 s (or --duration)")
    ap.add_argument("--duration", type=float, help="cap every run at S seconds of record")
    ap.add_argument("--full-scene", action="store_true", help="the El Centro scene run is not capped")
    ap.add_argument("--records", help="glob(s), comma-separated, on the record file names")
    ap.add_argument("--records-dir", help="ground-motion folder (default $VINES_GROUND_MOTIONS, "
                                          "else ../shared/data/ground_motions beside the repository)")
    ap.add_argument("--only", help="run kinds: " + ",".join(KINDS))
    ap.add_argument("--keep-scenes", metavar="DIR", help="write the scenes to DIR and keep them "
                                                            "(default: a temporary folder, removed)")
    ap.add_argument("-j", dest="jobs", type=int, default=1, help="benches (QEMU) at once, default 1")
    ap.add_argument("--json", action="store_true", help="one JSON object per target, one per line")
    ap.add_argument("--figures", metavar="FILE.md", help="also write the text report there, stamped with the "
                                                          "date, commit and machine (docs/figures/mcu.md); "
                                                          "not if a run failed")
    a = ap.parse_args()
    command = "python3 tools/mcu_report.py " + " ".join(sys.argv[1:])
    stamped = figures.stamp(command)  # the commit measured, not the one at the end

    a.targets = [t for t in a.targets.split(",") if t]
    for t in a.targets:
        if t not in TARGETS:
            raise Failure(f"unknown target {t!r} ({', '.join(TARGETS)})")
    a.schemes = [s for s in a.schemes.split(",") if s] if a.schemes else None
    if a.only:
        a.only = [k for k in a.only.split(",") if k]
        for k in a.only:
            if k not in KINDS:
                raise Failure(f"--only {k}: one of {', '.join(KINDS)}")
    if a.duration is not None and not (a.duration > 0 and math.isfinite(a.duration)):
        raise Failure("--duration must be > 0")
    if a.jobs < 1:
        raise Failure("-j must be >= 1")
    if a.bounded_substeps is not None and a.bounded_substeps < 1:
        raise Failure("--bounded-substeps must be >= 1")
    if a.split_steps is not None and a.split_steps < 1:
        raise Failure("--split-steps must be >= 1")

    vines = a.vines if os.path.isabs(a.vines) or os.path.exists(a.vines) else os.path.join(ROOT, a.vines)
    if not (os.path.isfile(vines) and os.access(vines, os.X_OK)):
        raise Failure(f"{a.vines}: no vines program (build it: cmake --preset release && "
                      f"cmake --build --preset release --target vines; or pass --vines PATH)")
    a.vines = os.path.abspath(vines)
    if shutil.which("qemu-system-arm") is None:
        raise Failure("qemu-system-arm not found (the boards run in QEMU)")
    records_dir = a.records_dir or os.environ.get("VINES_GROUND_MOTIONS") or \
        os.path.join(os.path.dirname(ROOT), "shared", "data", "ground_motions")

    with tempfile.TemporaryDirectory(prefix="mcu_report_") as tmp:
        if a.keep_scenes:
            os.makedirs(a.keep_scenes, exist_ok=True)
            tmp = os.path.abspath(a.keep_scenes)
        jobs = plan(a, tmp, records_dir)
        if not jobs:
            raise Failure("nothing to run (--only / --records)")
        missing = sorted({(j["target"], image_for(j)) for j in jobs if not os.path.isfile(image_for(j))})
        if missing:
            raise Failure("\n".join(f"{os.path.relpath(p, ROOT)}: not built (cmake --preset {t} && "
                                    f"cmake --build --preset {t})" for t, p in missing))
        images = {}
        for t in a.targets:
            for d in sorted({j["image"] for j in jobs if j["target"] == t}):
                images[(t, d)] = image_info(t, d)
        print(f"mcu_report: {len(jobs)} runs, {a.jobs} at once", file=sys.stderr, flush=True)
        complete = run_all(a.vines, jobs, a.jobs)

    failed = 0
    texts = []
    for t in a.targets:
        rep = report(t, jobs, images, a)
        failed += sum(1 for r in rep["runs"] if "error" in r)
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            print_text(rep)
        texts.append(text.getvalue())
        if a.json:
            print(json.dumps(rep), flush=True)
        else:
            print(texts[-1], end="")
    if a.figures and (failed or not complete):
        print(f"mcu_report: {a.figures} not written: the figures of a failed or interrupted report are not kept",
              file=sys.stderr)
    elif a.figures:
        figures.write(a.figures, "Boards: `tools/mcu_report.py`", command,
                      ["```text"] + "".join(texts).rstrip("\n").split("\n") + ["```"], stamped)
    if failed:
        print(f"mcu_report: {failed} run(s) failed or not run", file=sys.stderr)
    return 130 if not complete else 1 if failed else 0


# A Failure: its message, status 1. Ctrl-C before or after the runs (run_all handles its own): 130.
if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as e:
        print(f"mcu_report: {e}", file=sys.stderr)
        sys.exit(1)
    except KeyboardInterrupt:
        print("mcu_report: interrupted", file=sys.stderr)
        sys.exit(130)
