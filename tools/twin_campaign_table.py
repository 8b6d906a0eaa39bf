"""The twin campaign's table (tools/twin_benchmark.py): each run scored, rows of rates with the
issue's targets beside them, false alarms with a 95 % Wilson interval, the VI NES and TMD health.

A result is a dict: case (tools/twin_campaign_cases.py) and either twin (the report's "twin"
object), steps and wall, or error. The report's fields are read with .get(): a program without
onset_s, stories, sizes or story_identified gives "-" where they are needed.
"""
import math
import os
import statistics

# loss -> points of stiffness within which a size counts as right (issue 52's targets; 20 %: 2).
SIZE_PT = {0.03: 1.0, 0.05: 1.5, 0.10: 2.0, 0.20: 2.0}
LOCATE_WITHIN_S, ONSET_WITHIN_S, IMPULSE_SHARE = 20.0, 2.0, 0.25
# (family, loss) -> {column: (">=" | "<=", percent)}
TARGETS = {
    ("undamaged", 0.0): {"false alarms": ("<=", 1.0)},
    ("undamaged baseline", 0.0): {"false alarms": ("<=", 1.0)},
    ("before baseline", 0.10): {"located": (">=", 95.0), "size within": (">=", 95.0)},
    ("during", 0.10): {"located <=20 s": (">=", 95.0), "size within": (">=", 95.0)},
    ("during", 0.05): {"located": (">=", 90.0), "size within": (">=", 90.0), "onset within 2 s": (">=", 90.0)},
    ("during", 0.03): {"located": (">=", 80.0), "size within": (">=", 75.0)},
}
HEALTH_TARGETS = {"impulse within 25 %": (">=", 90.0), "stuck reported": (">=", 95.0),
                  "stuck on a moving sphere": ("<=", 0.0)}
DEVICE_NAMES = {"none": "bare", "tmd": "TMD", "vines": "VI NES", "all": "all"}


def wilson(k, n, z=1.959963984540054):
    """The Wilson score interval of a proportion k/n (95 % by default); (0, 1) when n is 0."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return max(0.0, centre - half), min(1.0, centre + half)


def named(t):
    """The stories the decision names: `stories`, else `story` (a program before the list)."""
    if t.get("stories") is not None:
        return list(t["stories"])
    return [t["story"]] if t.get("story") else []


def score(r):
    """One run's marks: detected, located, located within 20 s of the onset, size error [pt],
    onset error [s], delay [s] (from the truth's onset during the record, else the report's)."""
    c, t = r["case"], r["twin"]
    det = bool(t.get("detected"))
    damaged, loss, onset = c["damaged"], c["loss"], c.get("onset_s")
    stories = named(t)
    located = bool(damaged) and det and t.get("story_identified", True) is not False and \
        sorted(stories) == sorted(damaged)
    if len(damaged) > 1 and t.get("stories") is None:  # a report naming one story: one of them
        located = det and t.get("story") in damaged
    s = dict(detected=det, located=located, size_err=None, onset_err=None, delay=None, located20=None)
    if det and onset is not None and t.get("detect_time_s") is not None:
        s["delay"] = t["detect_time_s"] - onset
    elif det:
        s["delay"] = t.get("detect_delay_s")
    if onset is not None:
        s["located20"] = located and s["delay"] is not None and 0 <= s["delay"] <= LOCATE_WITHIN_S
        if det and t.get("onset_s") is not None:
            s["onset_err"] = abs(t["onset_s"] - onset)
    if located and len(damaged) == 1:
        sizes = t.get("sizes")
        size = sizes[stories.index(damaged[0])] if sizes else t.get("size")
        if size is not None:
            s["size_err"] = 100 * abs(size - loss)
    return s


def pct(k, n):
    return f"{100 * k / n:5.1f} %" if n else "-"


def stat(xs, fmt):
    if not xs:
        return "-"
    xs = sorted(xs)
    return (fmt % statistics.fmean(xs)) + " / " + (fmt % xs[min(len(xs) - 1, int(0.9 * len(xs)))])


def mark(value_pct, target):
    """' (>=95 ✓)' beside a figure: the target and whether the figure meets it."""
    if target is None or value_pct is None:
        return ""
    op, v = target
    ok = value_pct >= v if op == ">=" else value_pct <= v
    return f" ({op}{v:g} {'✓' if ok else '✗'})"


def share(flags, target=None):
    """'k/n' as a percentage with its target's mark; flags may hold None (not applicable)."""
    flags = [f for f in flags if f is not None]
    if not flags:
        return "-"
    k, n = sum(flags), len(flags)
    return pct(k, n) + mark(100 * k / n, target)


def group_key(r):
    c = r["case"]
    return ("SCT" if c["sct"] else "9 records", c["device"], c["family"], c["loss"], c["label"])


ORDER = {"undamaged": 0, "during": 1, "two during": 2, "before": 3, "undamaged baseline": 4, "before baseline": 5,
         "detuned": 6, "stuck": 7}
QUIET = ("undamaged", "undamaged baseline", "stuck")  # no damage: false alarms
BEFORE = ("before", "before baseline")
POOLED = {"undamaged": "undamaged", "undamaged baseline": "undamaged, baseline"}  # every device and record too
HEAD = ("records", "device", "truth", "runs", "failed", "detected", "located", "located <=20 s", "size err pt mean/p90",
        "size within", "onset err s mean/p90", "onset within 2 s", "delay s mean/p90", "false alarms [95 % CI]",
        "roof NRMSE mean/p90", "us/step")


def rows(results, bound_located=None):
    """The table's rows (tuples of strings, HEAD's columns): per records set (the nine records,
    SCT, every record: the targets hold for every record), device and truth; then every device
    and record together for the undamaged runs (the false alarm target counts them all).
    bound_located: family ("before", "before baseline") -> {loss: the bound tool's located
    share}, for the before-the-record rows' target (0.9 x it)."""
    groups = {}
    for r in results:
        k = group_key(r)
        groups.setdefault(k, []).append(r)
        groups.setdefault(("every record",) + k[1:], []).append(r)
        if r["case"]["family"] in POOLED:
            fam = r["case"]["family"]
            groups.setdefault(("every record", "all", fam, 0.0, POOLED[fam]), []).append(r)
    out = []
    section = {"9 records": 0, "SCT": 1, "every record": 2}
    for key in sorted(groups, key=lambda k: (section[k[0]], k[1] == "all", k[1], ORDER[k[2]], k[3])):
        where, device, family, loss, label = key
        rs = groups[key]
        ok = [r for r in rs if "twin" in r]
        sc = [score(r) for r in ok]
        tw = [r["twin"] for r in ok]
        tg = dict(TARGETS.get((family, loss), {}))
        bound = (bound_located or {}).get(family) or {}
        if family in BEFORE and loss in bound:
            tg["located"] = (">=", round(90 * bound[loss], 1))
        damaged = family in ("during", "two during") + BEFORE
        single = family == "during" or family in BEFORE
        det = [s["detected"] for s in sc]
        if family == "detuned":
            det = [bool(t.get("device", {}).get("detuned")) for t in tw]
        thr = SIZE_PT.get(loss)
        size_ok = [s["size_err"] is not None and s["size_err"] <= thr for s in sc] if single and thr else []
        fa = ""
        if family in QUIET:
            k, n = sum(det), len(det)
            lo, hi = wilson(k, n)
            fa = f"{k}/{n} = {pct(k, n).strip()} [{100 * lo:.1f}, {100 * hi:.1f}]" + \
                mark(100 * k / n if n else None, tg.get("false alarms")) if n else "-"
        us = [1e6 * r["wall"] / max(1, r["steps"]) for r in ok]
        out.append((where, DEVICE_NAMES[device], label, str(len(rs)), str(len(rs) - len(ok)),
                    share(det) if family not in QUIET else "",
                    share([s["located"] for s in sc], tg.get("located")) if damaged else "",
                    share([s["located20"] for s in sc], tg.get("located <=20 s")) if family.endswith("during") else "",
                    stat([s["size_err"] for s in sc if s["size_err"] is not None], "%.2f") if single else "",
                    (share(size_ok, tg.get("size within")) + f" <={thr:g} pt") if size_ok else "",
                    stat([s["onset_err"] for s in sc if s["onset_err"] is not None], "%.1f")
                    if family.endswith("during") else "",
                    share([s["onset_err"] is not None and s["onset_err"] <= ONSET_WITHIN_S for s in sc],
                          tg.get("onset within 2 s")) if family.endswith("during") else "",
                    stat([s["delay"] for s in sc if s["delay"] is not None], "%.1f"), fa,
                    stat([t["roof_displacement_nrmse"] for t in tw if t.get("roof_displacement_nrmse") is not None],
                         "%.4f"),
                    "%.0f" % statistics.fmean(us) if us else "-"))
    return out


def health(results):
    """The devices' health rows: (what, runs, share with its 95 % interval and target)."""
    def row(what, flags):
        k, n = sum(flags), len(flags)
        lo, hi = wilson(k, n)
        fig = f"{k}/{n} = {pct(k, n).strip()} [{100 * lo:.1f}, {100 * hi:.1f}]" if n else "-"
        return (what, str(n), fig + (mark(100 * k / n, HEALTH_TARGETS.get(what)) if n else ""))

    ok = [r for r in results if "twin" in r]
    vines = [r for r in ok if r["case"]["device"] == "vines"]
    free = [r for r in vines if r["case"]["family"] != "stuck"]
    dev = lambda r: r["twin"].get("device") or {}
    impulse = []
    for r in free:
        d = dev(r)
        truth, est = d.get("impulse_truth_ns"), d.get("impulse_estimated_ns")
        if truth and est is not None:
            impulse.append(abs(est - truth) <= IMPULSE_SHARE * truth)
    tmd = [r for r in ok if r["case"]["device"] == "tmd"]
    return [row("impulse within 25 %", impulse),
            row("stuck reported", [dev(r).get("sphere") == "stuck" for r in vines if r["case"]["family"] == "stuck"]),
            row("stuck on a moving sphere", [dev(r).get("sphere") == "stuck" for r in free]),
            row("TMD detuned reported, detuned truths",
                [bool(dev(r).get("detuned")) for r in tmd if r["case"]["family"] == "detuned"]),
            row("TMD detuned reported, its spring right",
                [bool(dev(r).get("detuned")) for r in tmd if r["case"]["family"] != "detuned"])]


def markdown(head, body):
    widths = [max([len(h)] + [len(r[i]) for r in body]) for i, h in enumerate(head)]
    line = lambda cells: "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths)) + " |"
    return "\n".join([line(head), "|" + "|".join("-" * (w + 2) for w in widths) + "|"] + [line(r) for r in body])


def failures(results, limit=20):
    """The failed runs, grouped by family and the message's first line: (count, family, example, message)."""
    groups = {}
    for r in results:
        if "error" in r:
            c = r["case"]
            msg = (r["error"].strip().splitlines() or ["?"])[-1][:160]
            groups.setdefault((c["family"], msg), []).append(
                f"{c['device']} {os.path.basename(c['record'])} seed {c['seed']}")
    return [(len(v), fam, v[0], msg) for (fam, msg), v in sorted(groups.items(), key=lambda kv: -len(kv[1]))][:limit]


def print_all(results, bound_located=None, out=print):
    out(markdown(HEAD, rows(results, bound_located)))
    out("")
    out(markdown(("device health", "runs", "share [95 % CI] (target)"), health(results)))
    fails = failures(results)
    if fails:
        out("")
        out(f"failed runs: {sum(1 for r in results if 'error' in r)}")
        for n, fam, example, msg in fails:
            out(f"  {n} x {fam} (e.g. {example}): {msg}")
