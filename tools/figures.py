#!/usr/bin/python3
"""Measured figures as files: docs/figures/*.md, each written whole by the tool
that measured it, stamped with the date, the commit and the machine, so that no
figure in the guides is edited by hand (docs/figures/README.md).

As a module (tools/mcu_report.py, tools/twin_benchmark.py): stamp() and write().
As a command, the work-precision table of a `vines bench --csv` file, the
bench's deadlines with and without the monitoring page (tools/page_deadlines.sh)
or real-time service (tools/realtime_deadlines.sh), the parts of tools/test.sh:

  figures.py bench BENCH.csv [--out docs/figures/bench.md] [--command CMD]
  figures.py deadlines RUNS.jsonl [--out docs/figures/page_deadlines.md] [--command CMD]
  figures.py realtime RUNS.jsonl [--out docs/figures/realtime_deadlines.md] [--command CMD]
  figures.py test-times TEST.log [--out docs/figures/test_times.md] [--command CMD]

Exit code 2, with a message naming the path, on a missing file or column.
"""
import argparse
import csv
import datetime
import json
import os
import platform
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIGURES = os.path.join(ROOT, "docs", "figures")


def _git(*args):
    try:
        return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def machine():
    """'AMD EPYC 7B13, 2 cores, 24 GiB, Linux 6.1' from /proc (or platform)."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    mem = ""
    try:
        with open("/proc/meminfo") as f:
            kb = int(f.readline().split()[1])
        mem = f", {kb / 2**20:.0f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    return f"{cpu}, {os.cpu_count()} cores{mem}, {platform.system()} {platform.release()}"


def stamp(command):
    """The lines that say where the figures come from."""
    commit = _git("rev-parse", "--short=12", "HEAD") or "unknown"
    dirty = " with local changes" if _git("status", "--porcelain", "--untracked-files=no") else ""
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return [f"Written by `{command}` on {now}, commit {commit}{dirty},",
            f"on {machine()}. Do not edit: run the command again."]


def fail(tool, message):
    """The message on stderr, exit code 2."""
    print(f"{tool}: {message}", file=sys.stderr)
    sys.exit(2)


def table(header, rows):
    """A markdown table."""
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return out


def write(path, title, command, body, stamped=None):
    """docs/figures/NAME.md: the title, the stamp (stamped: the lines stamp()
    gave when the measurement began, or now), the body lines; whole or not at
    all (a temporary file renamed over it)."""
    text = "\n".join([f"# {title}", ""] + (stamped or stamp(command)) + [""] + list(body)) + "\n"
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    tmp = os.path.join(folder, f".{os.path.basename(path)}.{os.getpid()}.tmp")
    try:
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except OSError as e:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        fail("figures.py", f"{path}: {e.strerror}")


# ---- the work-precision table of `vines bench --csv` ----

BENCH_COLUMNS = ["scene", "method", "contact_scheme", "scalar", "sensor_rate_hz", "contact_rtol", "wall_s_median",
                 "peak_rel_error", "contacts"]


def _g(v, fmt):
    try:
        x = float(v)
    except ValueError:
        return "-"
    return "-" if x != x else format(x, fmt)


def read_csv(path, columns, tool):
    """The rows of a CSV file; exit 2 naming the tool and the path on a file
    that cannot be read or lacks one of the columns (an empty file has none)."""
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(tool, f"{path}: {e.strerror}")
    for c in columns:
        if rows and c not in rows[0]:
            fail(tool, f"{path}: no column '{c}'")
    return rows


def bench_body(path):
    rows = read_csv(path, BENCH_COLUMNS, "figures.py")
    if not rows:
        fail("figures.py", f"{path}: no lines")
    body = []
    for scene in sorted({r["scene"].strip('"') for r in rows}):
        mine = [r for r in rows if r["scene"].strip('"') == scene]
        body += [f"## {scene}", ""]
        body += table(["method", "contact scheme", "scalar", "sensor rate Hz", "tolerance", "wall per run ms",
                       "peak error", "contacts"],
                      [[r["method"], r["contact_scheme"] if r["method"] == "firmware" else "-", r["scalar"], _g(r["sensor_rate_hz"], "g"), _g(r["contact_rtol"], "g"),
                        _g(1e3 * float(r["wall_s_median"]), ".3g"), _g(r["peak_rel_error"], ".1e"), r["contacts"]]
                       for r in mine])
        body.append("")
    return body


# ---- the bench's deadlines with and without the monitoring page ----

DEADLINE_KINDS = ["no page", "served, no client", "stream read, no browser", "page open"]


def _runs(path, keys):
    """The runs of a JSON-lines file, each with keys."""
    try:
        with open(path) as f:
            runs = [json.loads(line) for line in f if line.strip()]
    except OSError as e:
        fail("figures.py", f"{path}: {e.strerror}")
    except json.JSONDecodeError as e:
        fail("figures.py", f"{path}: line {e.lineno}: not JSON ({e.msg})")
    for r in runs:
        for key in keys:
            if key not in r:
                fail("figures.py", f"{path}: a run without '{key}'")
    if not runs:
        fail("figures.py", f"{path}: no runs")
    return runs


def _deadline_row(r):
    lat = r["latency_us"]
    return [r["kind"], r["round"], f"{r['load']:.2f}", r["steps"], r["deadline_misses"],
            f"{100 * r['deadline_misses'] / r['steps']:.3f}", f"{lat['mean']:.0f} / {lat['p99']:.0f} / {lat['max']:.0f}"]


DEADLINE_HEADER = ["run", "round", "load before", "steps", "deadline misses", "misses %",
                   "latency mean / p99 / max (us)"]


def deadlines_body(path):
    """The table of tests/browser/deadlines.js's JSON lines: one row a run."""
    runs = _runs(path, ("kind", "round", "load", "steps", "deadline_misses", "latency_us"))
    rows = [_deadline_row(r) + ["-" if r.get("page_samples") is None else r["page_samples"]]
            for r in sorted(runs, key=lambda r: (DEADLINE_KINDS.index(r["kind"]), r["round"]))]
    return table(DEADLINE_HEADER + ["samples on the page"], rows)


# ---- the bench's deadlines with and without real-time service ----

REALTIME_KINDS = ["time-shared", "real-time service"]


def _service(s):
    """One process's service as the report gives it: "FIFO 80, locked, core 1" or what was refused."""
    if not s:
        return "-"
    text = ("FIFO " + str(s["priority"]) if s["policy"] == "fifo" else s["policy"]) + \
        (", locked" if s["memory_locked"] else "") + \
        (f", core {s['cpus'][0]}" if len(s["cpus"]) == 1 else "")
    return text + "".join(f"; refused {r}" for r in s["refused"])


def realtime_body(path):
    """The table of tools/realtime_deadlines.sh's JSON lines: one row a run."""
    runs = _runs(path, ("kind", "round", "load", "steps", "deadline_misses", "latency_us", "service"))
    rows = []
    for r in sorted(runs, key=lambda r: (REALTIME_KINDS.index(r["kind"]), r["round"])):
        s = r["service"] or {}
        rows.append(_deadline_row(r) + [_service(s.get("bench")), _service(s.get("node"))])
    return table(DEADLINE_HEADER + ["bench", "node"], rows)


# ---- the parts of tools/test.sh and their times ----

def test_times_body(path):
    """The table of tools/test.sh's laps ("test.sh: PART at N s" lines)."""
    try:
        with open(path, errors="replace") as f:
            laps = [(m.group(1), int(m.group(2))) for m in (re.match(r"test\.sh: (.+) at (\d+) s$", line.rstrip())
                                                             for line in f) if m]
    except OSError as e:
        fail("figures.py", f"{path}: {e.strerror}")
    if not laps:
        fail("figures.py", f"{path}: no 'test.sh: ... at N s' lines (the output of bash tools/test.sh)")
    rows, before = [], 0
    for part, at in laps:
        rows.append([part, at - before, at])
        before = at
    return table(["part", "took s", "at s"], rows) + ["", f"Whole run: {laps[-1][1]} s ({laps[-1][1] / 60:.1f} min)."]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    sub = ap.add_subparsers(dest="what", required=True)
    b = sub.add_parser("bench", help="the work-precision table of a vines bench --csv file")
    b.add_argument("csv")
    b.add_argument("--out", default=os.path.join(FIGURES, "bench.md"))
    b.add_argument("--command", default="bash tools/bench.sh", help="the command the stamp names")
    d = sub.add_parser("deadlines", help="the bench's deadlines with and without the page (tools/page_deadlines.sh)")
    d.add_argument("jsonl")
    d.add_argument("--out", default=os.path.join(FIGURES, "page_deadlines.md"))
    d.add_argument("--command", default="bash tools/page_deadlines.sh")
    rt = sub.add_parser("realtime", help="the bench's deadlines with and without real-time service "
                        "(tools/realtime_deadlines.sh)")
    rt.add_argument("jsonl")
    rt.add_argument("--out", default=os.path.join(FIGURES, "realtime_deadlines.md"))
    rt.add_argument("--command", default="bash tools/realtime_deadlines.sh")
    t = sub.add_parser("test-times", help="the parts of tools/test.sh and their times, from its output")
    t.add_argument("log")
    t.add_argument("--out", default=os.path.join(FIGURES, "test_times.md"))
    t.add_argument("--command", default="bash tools/test.sh > test.log 2>&1; python3 tools/figures.py test-times test.log")
    a = ap.parse_args()
    if a.what == "test-times":
        write(a.out, "The parts of `tools/test.sh` and their times", a.command,
              ["`tools/test.sh` on a clean clone (no build folder, no compiler cache): the release build and its",
               "tests, the sanitizer subset (preset `sanitize`), then each board's images and their tests in",
               "QEMU. CI allows 90 minutes for the whole, `tools/setup.sh` included.", ""]
              + test_times_body(a.log))
        print(f"figures.py: wrote {a.out}")
        return
    if a.what == "realtime":
        write(a.out, "The bench's deadlines with and without real-time service", a.command,
              ["`vines hil data/scenes/elcentro_vines.toml --realtime` (1 kHz, host node), time-shared and with",
               "`--realtime-priority 80 --cpus 0,1` (SCHED_FIFO 80 and locked memory for the bench and its node,",
               "each on its own core), rounds interleaved, on an otherwise idle machine. A deadline is missed",
               "when a sample's telemetry is not back within one sensor period of the sample's due time;",
               "latency is from the sample's send to its telemetry. The service columns are what the OS",
               "granted, read back from it.", ""]
              + realtime_body(a.jsonl))
        print(f"figures.py: wrote {a.out}")
        return
    if a.what == "deadlines":
        write(a.out, "The bench's deadlines with and without the monitoring page", a.command,
              ["`vines hil data/scenes/elcentro_vines.toml --realtime` (1 kHz, host node): without `--serve`,",
               "with `--serve` and no client, with a client reading the event stream without drawing it, and",
               "with the page open in headless chromium on the same machine for the whole run",
               "(`tests/browser/deadlines.js`); rounds interleaved. A deadline is missed when a sample's",
               "telemetry is not back within one sensor period; latency is from the sample's send to its",
               "telemetry. Samples on the page: the kept samples (every 5th, and each in contact) the client",
               "received.", ""]
              + deadlines_body(a.jsonl))
        print(f"figures.py: wrote {a.out}")
        return
    write(a.out, "Work-precision: `vines bench` on the El Centro scenes", a.command,
          ["Wall time per full run (median of repeats, one core), peak top-floor displacement error",
           "against `data/reference/`, contacts (the reference's in `vines reference`).", ""]
          + bench_body(a.csv))
    print(f"figures.py: wrote {a.out}")


if __name__ == "__main__":
    main()
