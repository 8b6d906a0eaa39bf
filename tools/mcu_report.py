#!/usr/bin/python3
"""Cost of the firmware on each MCU target, measured: instructions per step
(El Centro, VI NES and TMD scenes, in QEMU with -icount), flash and RAM
(arm-none-eabi-size), worst stack depth (the call graph of -fcallgraph-info=su
plus every function's frame; cross-checked against the painted stack's
high-water mark measured in the run).

  tools/mcu_report.py [--json] [--targets cortex-m4f,cortex-m7]

Needs the presets built: cmake --build --preset release --target vines_feed
(the host end of the link), cmake --build --preset cortex-m4f / cortex-m7.
--json prints one JSON object per target, one per line.
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGETS = {  # preset: board, scalar, clock for the sustained-rate figure
    "cortex-m4f": ("mps2-an386", "float", 168e6),
    "cortex-m7": ("mps2-an500", "double", 480e6),
}
MARGIN = 1.5  # the step must fit in 2/3 of the period
IMAGES = ("vines", "tmd")


class Failure(Exception):
    pass


def sizes(elf):
    try:
        out = subprocess.run(["arm-none-eabi-size", "-A", elf], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        raise Failure(f"arm-none-eabi-size {elf}: {e}")
    sec = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[0].startswith(".") and parts[1].isdigit():
            sec[parts[0]] = int(parts[1])
    flash = sum(v for k, v in sec.items() if k in (
        ".isr_vector", ".text", ".ARM.extab", ".ARM.exidx", ".preinit_array", ".init_array", ".data"))
    ram = sec.get(".data", 0) + sec.get(".bss", 0)
    return flash, ram, sec.get(".stack", 0)


def call_graph(objdir):
    """Frames and edges from the .ci files (VCG) of one image's objects."""
    frames, edges, dynamic = {}, {}, set()
    files = glob.glob(os.path.join(objdir, "**", "*.ci"), recursive=True)
    if not files:
        raise Failure(f"no .ci files under {objdir}: reconfigure the preset from scratch "
                      "(the toolchain adds -fcallgraph-info=su)")
    node = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
    edge = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
    for path in files:
        with open(path) as f:
            text = f.read()
        for title, label in node.findall(text):
            m = re.search(r"(\d+) bytes \(([a-z,]+)\)", label)
            if m:
                frames[title] = max(frames.get(title, 0), int(m.group(1)))
                if m.group(2) != "static":
                    dynamic.add(title)
        for src, dst in edge.findall(text):
            edges.setdefault(src, set()).add(dst)
    return frames, edges, dynamic


def worst_stack(objdir, root="vines_start"):
    frames, edges, dynamic = call_graph(objdir)
    memo, unknown, cycles = {}, set(), set()

    def depth(fn, path):
        if fn in path:
            cycles.add(fn)
            return 0
        if fn in memo:
            return memo[fn]
        if fn not in frames:
            unknown.add(fn)  # library code built without call-graph info
        best = max((depth(c, path | {fn}) for c in edges.get(fn, ())), default=0)
        memo[fn] = frames.get(fn, 0) + best
        return memo[fn]

    total = depth(root, frozenset())
    reached = set(memo)
    return total, sorted(dynamic & reached), sorted(unknown), sorted(cycles)


def run_scene(target, board, scalar, device):
    build = os.path.join(ROOT, "build", target)
    cmd = [sys.executable, os.path.join(ROOT, "hal", "mcu", "scene_run.py"), "--board", board,
           "--image", os.path.join(build, "firmware", "app", f"vines_mcu_loop_{device}.elf"),
           "--feed-tool", os.path.join(ROOT, "build", "release", "vines_feed"),
           "--scene", os.path.join(ROOT, "data", "scenes", f"elcentro_{device}.toml"),
           "--scalar", scalar, "--rtol", "1", "--count-rtol", "1e6", "--json"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise Failure(f"{target} {device}: scene run failed:\n{r.stderr.strip()}")
    return json.loads(r.stdout)


def report(target):
    board, scalar, clock = TARGETS[target]
    build = os.path.join(ROOT, "build", target)
    elf = {d: os.path.join(build, "firmware", "app", f"vines_mcu_loop_{d}.elf") for d in IMAGES}
    for path in elf.values():
        if not os.path.isfile(path):
            raise Failure(f"{path}: not built (cmake --preset {target} && cmake --build --preset {target})")
    runs = {d: run_scene(target, board, scalar, d) for d in IMAGES}
    flash, ram, stack_reserved = sizes(elf["vines"])
    stacks = {d: worst_stack(os.path.join(build, "firmware", "app", "CMakeFiles", f"vines_mcu_loop_{d}.dir"))
              for d in IMAGES}
    # Worst of the call-graph bound and the painted measurement: the bound
    # misses dynamic (alloca) frames and library code, the measurement only
    # sees the paths this run took.
    worst_of = {d: max(stacks[d][0], runs[d]["stack_peak_bytes"]) for d in IMAGES}
    deepest = max(IMAGES, key=lambda d: worst_of[d])
    _, dynamic, unknown, cycles = stacks[deepest]
    stack = worst_of[deepest]
    v, t = runs["vines"], runs["tmd"]
    worst = max(r["all"]["max"] for r in runs.values())
    return {
        "target": target, "scalar": scalar, "board": board,
        "instructions_per_step_max": worst,
        "instructions_per_step_median": v["all"]["median"],
        "flash_bytes": flash, "ram_bytes": ram, "stack_bytes_max": stack,
        "stack_image": deepest, "stack_bytes_measured": runs[deepest]["stack_peak_bytes"],
        "stack_bytes_by_image": {d: {"call_graph": stacks[d][0], "measured": runs[d]["stack_peak_bytes"]}
                                 for d in IMAGES},
        "stack_reserved_bytes": stack_reserved,
        "stack_dynamic_frames": dynamic, "stack_unanalysed_callees": unknown, "stack_cycles": cycles,
        "vines_free_steps": v["free"], "vines_contact_steps": v["contact"], "tmd_steps": t["all"],
        "clock_hz": clock, "margin": MARGIN,
        "max_sensor_rate_hz": clock / (MARGIN * worst),
        "max_sensor_rate_hz_free_flight": clock / (MARGIN * max(v["free"]["max"], t["all"]["max"])),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true", help="one JSON object per target")
    ap.add_argument("--targets", default="cortex-m4f,cortex-m7")
    a = ap.parse_args()
    for target in a.targets.split(","):
        if target not in TARGETS:
            raise Failure(f"unknown target {target!r} (cortex-m4f or cortex-m7)")
        r = report(target)
        if a.json:
            print(json.dumps(r))
            continue
        print(f"{target} ({r['board']}, {r['scalar']}):")
        for name, key in (("VI NES free-flight steps", "vines_free_steps"),
                          ("VI NES contact steps", "vines_contact_steps"), ("TMD steps", "tmd_steps")):
            c = r[key]
            print(f"  {name:26s} {c['steps']:6d} steps, instructions/step max {c['max']:8.0f}, "
                  f"median {c['median']:8.0f}")
        print(f"  worst step {r['instructions_per_step_max']:.0f} instructions; at {r['clock_hz'] / 1e6:.0f} MHz, "
              f"1 instruction/cycle, {r['margin']:g}x margin: up to {r['max_sensor_rate_hz']:.0f} Hz sensor rate "
              f"({r['max_sensor_rate_hz_free_flight']:.0f} Hz without the contact steps)")
        print(f"  flash {r['flash_bytes']} B, RAM {r['ram_bytes']} B static (+{r['stack_reserved_bytes']} B "
              f"stacks reserved) (VI NES image)")
        for d, st in r["stack_bytes_by_image"].items():
            print(f"  stack, {d} image: {st['call_graph']} B worst path (call graph), {st['measured']} B "
                  f"measured (painted stack; the model build at start-up is the deepest)")
        if r["stack_dynamic_frames"]:
            print(f"    frames of dynamic size (alloca; the measured figure covers them): "
                  f"{len(r['stack_dynamic_frames'])}")
        if r["stack_unanalysed_callees"]:
            print(f"    callees without frame data (library code, counted 0): "
                  f"{', '.join(r['stack_unanalysed_callees'][:8])}"
                  f"{' ...' if len(r['stack_unanalysed_callees']) > 8 else ''}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as e:
        print(f"mcu_report: {e}", file=sys.stderr)
        sys.exit(1)
