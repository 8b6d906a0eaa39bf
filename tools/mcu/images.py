"""The board images: flash and RAM from their sections and the linker's stack
symbols (arm-none-eabi-size and -nm), the worst stack depth from vines_start
through the call graph that -fcallgraph-info=su writes beside the objects (.ci
files), and a hash of each ELF so that a run on an image rebuilt during the
report is flagged."""
import glob
import hashlib
import os
import re
import subprocess

from . import ROOT, Failure


# One program of the Arm toolchain: its output, or a Failure with its error.
def _tool(name, *args):
    try:
        return subprocess.run([name, *args], capture_output=True, text=True, check=True).stdout
    except OSError as e:
        raise Failure(f"{name}: {e.strerror} (install the Arm GNU toolchain)")
    except subprocess.CalledProcessError as e:
        raise Failure(f"{name} {' '.join(args)}: {e.stderr.strip()}")


# Flash and RAM of one image from its sections (arm-none-eabi-size -A) and the linker's
# stack symbols (arm-none-eabi-nm); the guard below the stack is not counted as RAM.
def sizes(elf):
    sec = {}
    for line in _tool("arm-none-eabi-size", "-A", elf).splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[0].startswith(".") and parts[1].isdigit():
            sec[parts[0]] = int(parts[1])
    sym = {}
    for line in _tool("arm-none-eabi-nm", elf).splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] in ("__stack_guard_size", "__stack_size", "__handler_stack_size"):
            sym[parts[2]] = int(parts[0], 16)
    flash = sum(v for k, v in sec.items() if k in (
        ".isr_vector", ".text", ".ARM.extab", ".ARM.exidx", ".preinit_array", ".init_array", ".data"))
    static = sec.get(".data", 0) + sec.get(".bss", 0)
    stack_section = sec.get(".stack", 0)
    guard = sym.get("__stack_guard_size", 0) if stack_section else 0
    return {
        "flash_bytes": flash,
        "ram_bytes": static + stack_section - guard,
        "ram_bytes_with_guard": static + stack_section,
        "ram_static_bytes": static, "data_bytes": sec.get(".data", 0), "bss_bytes": sec.get(".bss", 0),
        "stack_section_bytes": stack_section, "stack_guard_bytes": guard,
        "process_stack_bytes": sym.get("__stack_size"), "handler_stack_bytes": sym.get("__handler_stack_size"),
    }


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


# The deepest stack from root down the call graph, with the dynamic frames on it, the
# callees without call-graph info and the functions on a cycle.
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
            unknown.add(fn)  # library code built without call-graph info, or __indirect_call
        best = max((depth(c, path | {fn}) for c in edges.get(fn, ())), default=0)
        memo[fn] = frames.get(fn, 0) + best
        return memo[fn]

    total = depth(root, frozenset())
    return total, sorted(dynamic & set(memo)), sorted(unknown), sorted(cycles)


# A file's SHA-256, first 16 hex digits (None if unreadable): which image was sized, which ran.
def file_hash(path):
    try:
        with open(path, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()[:16]
    except OSError:
        return None


# One image as the report lists it: ELF, hash, sizes and the call-graph bound.
def image_info(target, device):
    build = os.path.join(ROOT, "build", target)
    elf = os.path.join(build, "firmware", "app", f"vines_node_{device}.elf")
    info = {"elf": os.path.relpath(elf, ROOT), "sha256": file_hash(elf)}
    info.update(sizes(elf))
    total, dynamic, unknown, cycles = worst_stack(
        os.path.join(build, "firmware", "app", "CMakeFiles", f"vines_node_{device}.dir"))
    info.update({"stack_bytes_call_graph": total, "call_graph_dynamic_frames": dynamic,
                 "call_graph_unanalysed_callees": unknown, "call_graph_cycles": cycles})
    return info
