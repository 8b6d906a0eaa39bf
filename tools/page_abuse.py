#!/usr/bin/env python3
"""The bench with its page abused (issue 53): `vines hil SCENE --serve 0` run twice, once with no
client and once while clients abuse the page: requests that dribble in a byte every 0.5 s, idle
sockets, a 1,600-range request, methods and Hosts refused, event-stream readers that stop
reading, a 64 KB header. Prints both reports' figures and checks that the abused run's report
is the clean run's (wall times and latencies apart; in lock step only), that it ended within its --serve-hold plus
5 s, that every abuse got its answer, and (with --realtime) prints the deadline misses of each
run beside docs/figures/page_deadlines.md's.

Usage: /usr/bin/python3 tools/page_abuse.py VINES SCENE [--duration S] [--realtime]
Exit 0 when every check holds, 1 otherwise.
"""
import argparse
import json
import re
import socket
import subprocess
import sys
import threading
import time

TIMING = {"wall_time_s", "latency_us", "deadline_misses", "node_deadline", "step_ticks", "steps_over_budget"}


def connect(port):
    return socket.create_connection(("127.0.0.1", port), timeout=10)


def listening(port):
    try:
        connect(port).close()
        return True
    except OSError:
        return False


def status(port, request):
    """The status line of a raw request's answer ('' if none came)."""
    try:
        with connect(port) as s:
            s.sendall(request.encode())
            got = b""
            while b"\r\n" not in got:
                chunk = s.recv(4096)
                if not chunk:
                    break
                got += chunk
            return got.split(b"\r\n")[0].decode()
    except OSError:
        return ""


def abuse(port, stop, found, alive):
    host = f"Host: 127.0.0.1:{port}\r\n"

    def dribble():  # a request line and headers a byte every 0.5 s
        t0 = time.monotonic()
        try:
            with connect(port) as s:
                s.sendall(f"GET / HTTP/1.1\r\n{host}X-Slow: ".encode())
                while not stop.is_set() and time.monotonic() - t0 < 30:
                    time.sleep(0.5)
                    s.sendall(b"a")
        except OSError:
            pass
        found.setdefault("dribble_cut_s", []).append(round(time.monotonic() - t0, 1))

    def unread():  # an event stream never read
        try:
            s = connect(port)
            s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            s.sendall(f"GET /events HTTP/1.1\r\n{host}\r\n".encode())
            stop.wait(30)
            s.close()
        except OSError:
            pass

    threads = [threading.Thread(target=dribble) for _ in range(4)] + [threading.Thread(target=unread) for _ in range(2)]
    for t in threads:
        t.start()
    idle = [connect(port) for _ in range(16)]
    many = "bytes=0-" + ",0-" * 1600
    checks = {
        "ranges": (f"GET / HTTP/1.1\r\n{host}Range: {many}\r\n\r\n", "HTTP/1.1 416"),
        "post": (f"POST /events HTTP/1.1\r\n{host}Content-Length: 1\r\n\r\nx", "HTTP/1.1 405"),
        "rebinding": ("GET /events HTTP/1.1\r\nHost: evil.example\r\n\r\n", "HTTP/1.1 421"),
        "big header": (f"GET / HTTP/1.1\r\n{host}X-Big: {'b' * 65536}\r\n\r\n", "not 200"),
        "page": (f"GET / HTTP/1.1\r\n{host}\r\n", "HTTP/1.1 200"),
    }
    while not stop.is_set():
        for name, (req, want) in checks.items():
            got = status(port, req)
            if not alive() or (got == "" and not listening(port)):  # the run over: its page stopped
                break
            # a header too big: refused, by an answer or by closing the connection
            ok = not got.startswith("HTTP/1.1 200") if want == "not 200" else got.startswith(want)
            found.setdefault(name, set()).add("ok" if ok else f"got '{got}'")
        stop.wait(1.0)
    for s in idle:
        s.close()
    for t in threads:
        t.join()


def run(vines, scene, args, abused):
    cmd = [vines, "hil", scene, "--serve", "0", "--serve-hold", "3", "--json", "--duration", str(args.duration)]
    if args.realtime:
        cmd.append("--realtime")
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    found, stop, worker = {}, threading.Event(), None
    line = p.stderr.readline()
    m = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
    if not m:
        sys.exit(f"page_abuse: no page address from vines hil: {line}{p.stderr.read()}")
    if abused:
        worker = threading.Thread(target=abuse, args=(int(m.group(1)), stop, found, lambda: p.poll() is None))
        worker.start()
    try:
        out, err = p.communicate(timeout=args.duration * 3 + 60)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        found["hang"] = True
    elapsed = time.monotonic() - t0
    stop.set()
    if worker:
        worker.join()
    report = json.loads(out) if out.strip() else {}
    return report, elapsed, found, err


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("vines")
    ap.add_argument("scene")
    ap.add_argument("--duration", type=float, default=20.0)
    ap.add_argument("--realtime", action="store_true")
    args = ap.parse_args()
    failures = []
    clean, t_clean, _, _ = run(args.vines, args.scene, args, False)
    dirty, t_dirty, found, err = run(args.vines, args.scene, args, True)
    budget = (args.duration if args.realtime else 0) + 3 + 5 + max(0.0, t_clean)
    print(f"clean run: {t_clean:.1f} s, deadline misses {clean.get('deadline_misses')}")
    print(f"abused run: {t_dirty:.1f} s, deadline misses {dirty.get('deadline_misses')}")
    for name, seen in sorted(found.items()):
        print(f"  {name}: {sorted(seen) if isinstance(seen, set) else seen}")
    if found.get("hang") or not dirty:
        failures.append(f"the abused run did not end or printed no report: {err[-300:]}")
    if t_dirty > budget:
        failures.append(f"the abused run took {t_dirty:.1f} s (clean {t_clean:.1f} s, budget {budget:.1f} s)")
    # In real time a late sample changes the run itself (the node holds the
    # last one): only lock-step runs are compared whole.
    same = {k: v for k, v in clean.items() if k not in TIMING}
    if dirty and not args.realtime and {k: v for k, v in dirty.items() if k not in TIMING} != same:
        diff = [k for k in same if dirty.get(k) != same[k]]
        failures.append(f"the abused run's report differs from the clean run's in {diff}")
    for name in ("ranges", "post", "rebinding", "big header", "page"):
        if found.get(name, set()) - {"ok"}:
            failures.append(f"{name}: {sorted(found[name])}")
    cuts = found.get("dribble_cut_s", [])
    if len(cuts) != 4 or max(cuts) > 8:
        failures.append(f"the dribbling requests were cut after {cuts} s (expected 4, each within 8 s)")
    for f in failures:
        print(f"page_abuse: {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
