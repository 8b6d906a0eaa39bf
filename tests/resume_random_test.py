#!/usr/bin/python3
"""A sweep's resume proves its log (sim_host/studies/sweep_log.hpp), under random
kill points and random damage to DIR/runs.jsonl: every `vines sweep --resume`
either gives the uninterrupted sweep's results.csv, byte for byte, or is
refused (exit 1) with a message naming the log. Anything else fails: a resume
that succeeds with other results, a crash, another exit status.

Damage (on a finished log of tests/data/mini_sweep.toml, each trial one to
three of them): a cut at a random byte (a power cut), a random byte changed,
a line dropped, a line duplicated, the lines shuffled, another sweep's header.
Kills: the initial-conditions study (data/studies/initial_conditions.toml,
2,000 runs) killed (SIGKILL) at a random time, then resumed.

Usage: resume_random_test.py VINES SOURCE_DIR [--trials N] [--kills N] [--seed S]
Standard library only.
"""
import argparse
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time


def sweep(vines, spec, *args):
    return subprocess.run([vines, "sweep", spec, "--no-progress", *args], capture_output=True, text=True)


def damage(rng, lines):
    """lines: the log's lines (header first, each with its newline); returns the damaged text and what was done."""
    kind = rng.choice(["cut", "byte", "drop", "duplicate", "shuffle", "header"])
    head, runs = lines[0], lines[1:]
    if kind == "drop" and runs:
        del runs[rng.randrange(len(runs))]
    elif kind == "duplicate" and runs:
        runs.insert(rng.randrange(len(runs) + 1), rng.choice(runs))
    elif kind == "shuffle":
        rng.shuffle(runs)
    elif kind == "header":
        head = head.replace('"fingerprint":"', '"fingerprint":"0', 1)
    text = head + "".join(runs)
    if kind == "cut":
        text = text[:rng.randrange(len(text))]
    elif kind == "byte":
        at = rng.randrange(len(text))
        text = text[:at] + chr(rng.randrange(32, 127)) + text[at + 1:]
    return text, kind


def judge(p, reference, folder, what):
    """'same' or 'refused'; exits with a message otherwise."""
    if p.returncode == 0:
        with open(os.path.join(folder, "results.csv")) as f:
            if f.read() == reference:
                return "same"
        sys.exit(f"resume_random_test: {what}: the resume succeeded with other results")
    if p.returncode == 1 and "runs.jsonl" in p.stderr:
        return "refused"
    sys.exit(f"resume_random_test: {what}: exit {p.returncode}: {p.stderr.strip()[-400:]}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("vines")
    ap.add_argument("src")
    ap.add_argument("--trials", type=int, default=200)
    ap.add_argument("--kills", type=int, default=6)
    ap.add_argument("--seed", type=int, default=20261125)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    tmp = tempfile.mkdtemp(prefix="vines_resume_")
    try:
        # Damaged logs of the mini sweep.
        spec = os.path.join(a.src, "tests", "data", "mini_sweep.toml")
        ref = os.path.join(tmp, "ref")
        p = sweep(a.vines, spec, "--out", ref)
        if p.returncode != 0:
            sys.exit(f"resume_random_test: the reference sweep failed: {p.stderr}")
        reference = open(os.path.join(ref, "results.csv")).read()
        lines = open(os.path.join(ref, "runs.jsonl")).read().splitlines(keepends=True)
        counts = {}
        for t in range(a.trials):
            work = os.path.join(tmp, f"t{t}")
            shutil.copytree(ref, work)
            text, kinds = "".join(lines), []
            for _ in range(rng.randint(1, 3)):
                text, kind = damage(rng, text.splitlines(keepends=True) or [""])
                kinds.append(kind)
            with open(os.path.join(work, "runs.jsonl"), "w") as f:
                f.write(text)
            verdict = judge(sweep(a.vines, spec, "--resume", work), reference, work, f"trial {t} ({'+'.join(kinds)})")
            counts[verdict] = counts.get(verdict, 0) + 1
            shutil.rmtree(work)
        print(f"damage: {a.trials} trials, {counts.get('same', 0)} resumed to the uninterrupted results, "
              f"{counts.get('refused', 0)} refused naming the log")

        # Kills at random times, then a resume.
        ic = os.path.join(tmp, "ic.toml")
        with open(os.path.join(a.src, "data", "studies", "initial_conditions.toml")) as f:
            open(ic, "w").write(f.read().replace('scene = "../', f'scene = "{a.src}/data/'))
        ref = os.path.join(tmp, "ic_ref")
        t0 = time.monotonic()
        p = sweep(a.vines, ic, "--out", ref)
        whole = time.monotonic() - t0
        if p.returncode != 0:
            sys.exit(f"resume_random_test: the reference sweep failed: {p.stderr}")
        reference = open(os.path.join(ref, "results.csv")).read()
        counts = {}
        for k in range(a.kills):
            work = os.path.join(tmp, f"k{k}")
            child = subprocess.Popen([a.vines, "sweep", ic, "--no-progress", "--out", work],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(rng.uniform(0.05, 0.9) * whole)
            child.send_signal(signal.SIGKILL)
            child.wait()
            if not os.path.exists(os.path.join(work, "runs.jsonl")):
                continue
            verdict = judge(sweep(a.vines, ic, "--resume", work), reference, work, f"kill {k}")
            counts[verdict] = counts.get(verdict, 0) + 1
        print(f"kills: {a.kills} sweeps killed at random times ({whole:.1f} s whole), "
              f"{counts.get('same', 0)} resumed to the uninterrupted results, {counts.get('refused', 0)} refused")
        if counts.get("refused", 0):
            sys.exit("resume_random_test: a killed sweep's log was refused (a kill must leave a log that resumes)")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("resume_random_test: ok")


if __name__ == "__main__":
    main()
