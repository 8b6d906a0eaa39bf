#!/usr/bin/env python3
"""A board image on the byte paths a lab's board takes: QEMU's UART on a TCP
socket (-serial tcp:...,server=on,wait=on, `vines hil --node tcp:...`) and on
a pseudo-terminal (-serial pty, `vines hil --node serial:/dev/pts/N`), each
run held bit for bit against the same image over the bench's pipe
(`--node qemu:TARGET`). Exit 0 if every output column of every step is equal,
1 with the first difference.

  link_check.py VINES TARGET MACHINE SCALAR IMAGE SCENE [--duration S] [--baud B]

The line runs get SCENE with [loop] scalar = SCALAR (what `--node qemu:`
imposes: the bench cannot know a board beyond a socket or a line). Columns of
the link's timing (latency_us) are not outputs and are not compared.
Standard library only."""
import csv
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile

TIMING = {"latency_us"}


def qemu(machine, image, serial):
    return subprocess.Popen(
        ["qemu-system-arm", "-M", machine, "-display", "none", "-monitor", "none",
         "-semihosting-config", "enable=on,target=native", "-serial", serial,
         "-icount", "shift=3,align=off,sleep=off", "-kernel", image],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def wait_for(proc, pattern):
    """The first match of pattern in what QEMU prints, or None if it ends first."""
    for line in proc.stdout:
        sys.stdout.write("qemu: " + line)
        m = re.search(pattern, line)
        if m:
            return m
    return None


def run(cmd):
    print("running:", " ".join(cmd), flush=True)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    sys.stdout.write(p.stdout[-2000:])
    sys.stderr.write(p.stderr)
    return p.returncode


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def compare(name, ref, got):
    if len(ref) != len(got):
        return f"{name}: {len(got)} rows, the pipe run {len(ref)}"
    for a, b in zip(ref, got):
        for col, v in a.items():
            if col not in TIMING and b.get(col) != v:
                return f"{name}: step {a.get('k')} column {col}: {b.get(col)}, the pipe run {v}"
    return None


def main(argv):
    args = argv[1:]
    duration, baud = "3", "3000000"
    while len(args) > 6:
        if args[-2] == "--duration":
            duration = args[-1]
        elif args[-2] == "--baud":
            baud = args[-1]
        else:
            sys.exit(__doc__)
        args = args[:-2]
    if len(args) != 6:
        sys.exit(__doc__)
    vines, target, machine, scalar, image, scene = args
    work = tempfile.mkdtemp(prefix="vines_link_check_")
    text = open(scene).read()
    line_scene = os.path.join(work, os.path.basename(scene))
    if re.search(r"^scalar *=", text, flags=re.M):
        text = re.sub(r"^scalar *=.*$", f"scalar = \"{scalar}\"", text, count=1, flags=re.M)
    else:
        text = re.sub(r"^\[loop\]\n", f"[loop]\nscalar = \"{scalar}\"\n", text, count=1, flags=re.M)
    with open(line_scene, "w") as f:
        f.write(text)
    base = ["hil", "--duration", duration, "--timeout", "60", "--json"]
    pipe_csv = os.path.join(work, "pipe.csv")
    if run([vines, *base, scene, "--node", "qemu:" + target, "--image", image, "--csv", pipe_csv]) != 0:
        print("FAIL: the pipe run failed")
        return 1
    ref = rows(pipe_csv)
    failures = []

    with socket.socket() as s:  # a free port
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    lines = [("tcp", f"tcp:127.0.0.1:{port},server=on,wait=on", r"waiting for connection",
              lambda m: f"tcp:127.0.0.1:{port}"),
             ("pty", "pty", r"char device redirected to (/dev/pts/\d+)", lambda m: f"serial:{m.group(1)}@{baud}")]
    for name, serial, says, node in lines:
        q = qemu(machine, image, serial)
        m = wait_for(q, says)
        if not m:
            failures.append(f"{name}: QEMU did not open its serial port ({serial})")
        else:
            out = os.path.join(work, name + ".csv")
            rc = run([vines, *base, line_scene, "--node", node(m), "--csv", out])
            failures.append(f"{name}: vines hil exit {rc}" if rc != 0 else compare(name, ref, rows(out)))
        q.kill()
        q.wait()

    failures = [f for f in failures if f]
    for f in failures:
        print("FAIL:", f)
    if failures:
        print(f"the runs' files: {work}")
        return 1
    print(f"ok: {len(ref)} steps over TCP and over a pty, every output column equal to the pipe run's")
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
