#!/usr/bin/python3
"""The monitoring page's event stream of a `vines hil` run, read to its end as
a client reads it (with the host node, or a board in QEMU: the MCU presets'
mcu_hil_page test):

  page_stream_check.py VINES SCENE [HIL OPTIONS...]

runs `VINES hil SCENE [HIL OPTIONS] --serve 0 --serve-hold 120 --csv TMP --json`,
reads /events to its end and checks: the meta event first, its series all
columns of the --csv; the frames hold exactly the samples the page keeps
(every `every`th sample received, and each in contact where the node runs
the VI NES's model) with the CSV's values, bit for bit (the columns the CSV
writes with 9 digits, the twin's truth and estimates, within 1e-8); the report event with the --json report's steps; then
the end event. Standard library only.

Exit 0: passed; 1: failed (each failure printed); 77: this vines has no page.
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import threading
import urllib.request


# The columns the CSV writes with 17 digits (the others, the twin's truth and
# estimates, with 9).
EXACT = {"ag_sent_mps2", "x_top_m", "particle_x_m", "contact_force_n", "flags", "aux", "alarm_story", "table_x_m",
         "force_measured_n"}


# The twin decision's series the page has from the telemetry and the --csv
# does not write (sim_host/monitor/rows.hpp: kDecisionSeries).
DECISION_ONLY = {"second_story", "damage_size", "second_size", "onset_s"}


def events(url):
    """The (name, data) of each Server-Sent Event of url, to the end event."""
    with urllib.request.urlopen(url, timeout=120) as r:
        name = None
        for raw in r:
            line = raw.decode("utf-8").rstrip("\n")
            if line.startswith("event: "):
                name = line[7:]
            elif line.startswith("data: "):
                yield name, json.loads(line[6:])
                if name == "end":
                    return


def main():
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    vines, scene, options = sys.argv[1], sys.argv[2], sys.argv[3:]
    failures = []

    def check(ok, message):
        if not ok:
            failures.append(message)
            print(f"FAIL: {message}")
        return ok

    with tempfile.TemporaryDirectory() as work:
        path = os.path.join(work, "run.csv")
        cmd = [vines, "hil", scene, *options, "--serve", "0", "--serve-hold", "120", "--csv", path, "--json"]
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        err, found = [], threading.Event()
        url = []

        def drain():
            for line in p.stderr:
                err.append(line)
                m = re.search(r"the page is at (http://\S+)", line)
                if m and not found.is_set():
                    url.append(m.group(1))
                    found.set()
            found.set()

        t = threading.Thread(target=drain)
        t.start()
        found.wait(300)
        if not url:
            p.wait()
            t.join()
            text = "".join(err)
            if "built without the monitoring page" in text:
                print("SKIP: " + text.strip())
                return 77
            print(f"FAIL: {' '.join(cmd)}: no page (exit {p.returncode}): {text.strip()}")
            return 1
        got = list(events(url[0] + "events"))
        out = p.stdout.read()
        p.wait()
        t.join()
        if not check(p.returncode == 0, f"vines hil exit {p.returncode}: {''.join(err).strip()}"):
            return 1
        report = json.loads(out)
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))

    names = [name for name, _ in got]
    check(names[0] == "meta" and names[-2:] == ["report", "end"], f"events {names[0]} ... {names[-2:]}")
    meta = got[0][1]
    series = [s["name"] for s in meta["series"]]
    every = meta["every"]
    missing = [s for s in series if s != "tracking_rms_pct" and s not in DECISION_ONLY and s not in rows[0]]
    check(not missing, f"series not in the CSV: {missing}")
    # The samples the page keeps, from the CSV.
    contact = "contact_force_n" in series and "particle_x_m" in series
    kept = [r for r in rows if r["received"] == "1" and
            (int(r["k"]) % every == 0 or (contact and float(r["contact_force_n"]) != 0))]
    ks, values = [], [[] for _ in series]
    for name, data in got:
        if name == "frame":
            ks += data["k"]
            for j, v in enumerate(data["v"]):
                values[j] += v
    check(ks == [int(r["k"]) for r in kept], f"kept samples: the stream {len(ks)}, the CSV {len(kept)}")
    worst = {}
    for j, s in enumerate(series):
        if s in missing or s == "tracking_rms_pct" or (s in DECISION_ONLY and s not in rows[0]):
            continue
        tol = 0.0 if s in EXACT or re.fullmatch(r"x_\d+_m", s) else 1e-8
        for v, r in zip(values[j], kept):
            want = float(r[s])
            d = abs((float("nan") if v is None else v) - want) / (max(1.0, abs(want)) if tol else 1.0)
            if not d <= tol:
                worst[s] = max(worst.get(s, 0.0), d)
    check(not worst, f"values off the CSV: {worst}")
    rep = got[-2][1]
    check(rep.get("steps") == report["steps"] and rep.get("node") == report["node"],
          f"report event: steps {rep.get('steps')}, node {rep.get('node')}; --json: {report['steps']}, {report['node']}")
    in_contact = sum(1 for r in kept if contact and float(r["contact_force_n"]) != 0)
    print(f"page stream of {report['node']}: {len(ks)} samples x {len(series)} series equal to the CSV "
          f"({in_contact} in contact), report of {report['steps']} steps, then the end")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
