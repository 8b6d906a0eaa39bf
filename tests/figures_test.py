#!/usr/bin/python3
"""tools/figures.py and tools/plot_bench.py on small `vines bench --csv` files:
the table's rows and stamp, and the refusals (exit 2 naming the file); the
parts of tools/test.sh from a small log; the deadlines with and without
real-time service from two runs.

Usage: figures_test.py REPO_ROOT
"""
import os
import subprocess
import sys
import tempfile

ROOT = sys.argv[1]
FIGURES = os.path.join(ROOT, "tools", "figures.py")
PLOT = os.path.join(ROOT, "tools", "plot_bench.py")
HEADER = "scene,method,contact_scheme,scalar,sensor_rate_hz,contact_rtol,wall_s_median,peak_rel_error,contacts\n"
ROWS = ('"elcentro_vines",firmware,adaptive,double,1000,1e-08,0.0014812,3.21e-09,18\n'
        '"elcentro_vines",dop853,adaptive,double,50,1e-08,0.0110,2.0e-07,18\n'
        '"elcentro_tmd",firmware,adaptive,float,50,,0.000321,null,0\n')
failures = []


def run(*args):
    return subprocess.run(["/usr/bin/python3", *args], capture_output=True, text=True)


def check(what, ok):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


with tempfile.TemporaryDirectory() as tmp:
    good = os.path.join(tmp, "bench.csv")
    with open(good, "w") as f:
        f.write(HEADER + ROWS)
    out = os.path.join(tmp, "figures", "bench.md")
    r = run(FIGURES, "bench", good, "--out", out, "--command", "bash tools/bench.sh --min-time 1")
    check("bench table written (exit 0)", r.returncode == 0 and os.path.exists(out))
    text = open(out).read() if os.path.exists(out) else ""
    check("stamp names the command, a commit and the machine",
          "Written by `bash tools/bench.sh --min-time 1` on " in text and ", commit " in text
          and "cores" in text)
    check("one section a scene, sorted", text.find("## elcentro_tmd") < text.find("## elcentro_vines") and
          text.count("## ") == 2)
    check("wall time in ms, error, contacts", "| firmware | adaptive | double | 1000 | 1e-08 | 1.48 | 3.2e-09 | 18 |" in text)
    check("the baselines' rows have no contact scheme", "| dop853 | - | double | 50 |" in text)
    check("a missing number is a dash", "| firmware | adaptive | float | 50 | - | 0.321 | - | 0 |" in text)
    check("no temporary file left", sorted(os.listdir(os.path.dirname(out))) == ["bench.md"])

    bad = os.path.join(tmp, "bad.csv")
    with open(bad, "w") as f:
        f.write("scene,method\nx,firmware\n")
    empty = os.path.join(tmp, "empty.csv")
    with open(empty, "w") as f:
        f.write(HEADER)
    missing = os.path.join(tmp, "missing.csv")
    for tool, args in ((FIGURES, ["bench"]), (PLOT, [])):
        name = os.path.basename(tool)
        for path, says in ((bad, "no column 'contact_scheme'" if tool == FIGURES else "no column 'scalar'"),
                           (empty, "no lines"), (missing, "No such file")):
            r = run(tool, *args, path, "--out", os.path.join(tmp, "x.out"))
            check(f"{name} {os.path.basename(path)}: exit 2 naming it ({says})",
                  r.returncode == 2 and f"{name}: {path}: " in r.stderr and says in r.stderr)
    check("nothing written on a refusal", not os.path.exists(os.path.join(tmp, "x.out")))

    # The parts of tools/test.sh from its output: each part's time is the
    # difference of its lap and the one before.
    log = os.path.join(tmp, "test.log")
    with open(log, "w") as f:
        f.write("setup: ok\ntest.sh: packages ready at 2 s\n[ 50%] Building x\ntest.sh: release built at 700 s\n"
                "test.sh: release tested at 1000 s\ntest.sh: all passed in 1000 s\n")
    out = os.path.join(tmp, "figures", "test_times.md")
    r = run(FIGURES, "test-times", log, "--out", out)
    text = open(out).read() if os.path.exists(out) else ""
    check("test times: one row a part, its time and when it ended",
          r.returncode == 0 and "| packages ready | 2 | 2 |" in text and "| release built | 698 | 700 |" in text
          and "| release tested | 300 | 1000 |" in text and "Whole run: 1000 s (16.7 min)." in text)
    r = run(FIGURES, "test-times", good, "--out", os.path.join(tmp, "x.out"))
    check("test times: a file without laps is refused, naming it",
          r.returncode == 2 and f"figures.py: {good}: no 'test.sh: " in r.stderr and not os.path.exists(os.path.join(tmp, "x.out")))

    # The deadlines with and without real-time service: one row a run, what
    # the OS granted each process, or what it refused.
    runs = os.path.join(tmp, "rt.jsonl")
    lat = '"latency_us": {"mean": 12.4, "p99": 40.2, "max": 900.0}'
    granted = ('{"policy": "fifo", "priority": 80, "memory_locked": true, "cpus": [1], "refused": []}')
    refused = ('{"policy": "other", "priority": 0, "memory_locked": false, "cpus": [0, 1], '
               '"refused": ["SCHED_FIFO priority 80: Operation not permitted"]}')
    with open(runs, "w") as f:
        f.write('{"kind": "real-time service", "round": 1, "load": 0.1, "steps": 20001, "deadline_misses": 1, '
                f'{lat}, "service": {{"bench": {refused}, "node": {granted}}}}}\n')
        f.write(f'{{"kind": "time-shared", "round": 1, "load": 0.0, "steps": 20001, "deadline_misses": 50, {lat}, '
                '"service": null}\n')
    out = os.path.join(tmp, "figures", "realtime_deadlines.md")
    r = run(FIGURES, "realtime", runs, "--out", out)
    text = open(out).read() if os.path.exists(out) else ""
    check("real-time deadlines: time-shared first, misses in %, each process's service",
          r.returncode == 0 and text.find("| time-shared |") < text.find("| real-time service |")
          and "| time-shared | 1 | 0.00 | 20001 | 50 | 0.250 | 12 / 40 / 900 | - | - |" in text
          and "| 0.005 | 12 / 40 / 900 | other; refused SCHED_FIFO priority 80: Operation not permitted | "
              "FIFO 80, locked, core 1 |" in text)
    with open(runs, "w") as f:
        f.write(f'{{"kind": "time-shared", "round": 1, "load": 0.0, "steps": 20001, "deadline_misses": 50, {lat}}}\n')
    r = run(FIGURES, "realtime", runs, "--out", os.path.join(tmp, "x.out"))
    check("real-time deadlines: a run without its service is refused, naming the file",
          r.returncode == 2 and f"figures.py: {runs}: a run without 'service'" in r.stderr)

print(f"figures_test: {len(failures)} failed")
sys.exit(1 if failures else 0)
