#!/usr/bin/env python3
"""tools/twin_benchmark.py, the twin campaign: its design, its table's arithmetic, one tiny run.

The design (tools/twin_campaign_cases.py): onsets inside the record's 25-75 % Arias span, healthy
stories within 3 %, masses within 2 %, every story and loss covered, the same campaign for the same
seed, the duration rule, Mexico City SCT on lines of its own. The table
(tools/twin_campaign_table.py) on a synthetic list of results: rates, the Wilson interval against
a root-finding of its definition. Then `vines hil` through the tool, when the program is built.
Usage: twin_campaign_test.py SOURCE_DIR [VINES]   (or pytest with VINES_SOURCE_DIR / VINES_EXE)
"""
import json
import os
import random
import subprocess
import sys
import tempfile

import pytest

SOURCE = os.environ.get("VINES_SOURCE_DIR") or os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(SOURCE, "tools"))
import twin_benchmark as tb  # noqa: E402
import twin_campaign_baseline as cb  # noqa: E402
import twin_campaign_cases as cc  # noqa: E402
import twin_campaign_table as ct  # noqa: E402

VINES = os.environ.get("VINES_EXE") or os.path.join(SOURCE, "build", "release", "vines")
RECORDS_DIR = os.environ.get("VINES_GROUND_MOTIONS") or os.path.join(SOURCE, "..", "shared", "data", "ground_motions")
HAVE_RECORDS = all(os.path.isfile(os.path.join(RECORDS_DIR, n)) for n in cc.RECORDS)


def fake_records():
    """record_info()-like entries for every record name: made-up Arias times, SCT's late."""
    rng, out = random.Random(3), []
    for name in cc.RECORDS:
        t05 = 39.6 if cc.is_sct(name) else rng.uniform(1, 5)
        t25, t75, t95 = t05 + 5, t05 + 15, t05 + rng.uniform(20, 40)
        length = t95 + rng.uniform(0, 80)
        out.append(dict(path=os.path.join("/records", name), name=name, length_s=length, t05=t05, t25=t25, t75=t75,
                        t95=t95, duration_s=cc.run_duration(t95, length), sct=cc.is_sct(name)))
    return out


@pytest.fixture(scope="module", params=[False, True], ids=["default", "quick"])
def design(request):
    recs = fake_records()
    return request.param, recs, cc.cases(recs, quick=request.param, seed=11)


def test_onsets_inside_the_arias_span(design):
    _, recs, cases = design
    by = {r["path"]: r for r in recs}
    during = [c for c in cases if c["family"] in ("during", "two during")]
    assert during
    for c in during:
        r = by[c["record"]]
        assert r["t25"] <= c["onset_s"] <= r["t75"]
        assert c["truth"]["damage"]["time_s"] == c["onset_s"]
        f = c["truth"]["damage"]["stiffness_scales"]
        assert [i + 1 for i, x in enumerate(f) if x != 1.0] == c["damaged"]
        assert all(abs(f[s - 1] - (1 - c["loss"])) < 1e-12 for s in c["damaged"])
    for c in cases:
        if c["family"] not in ("during", "two during"):
            assert c["onset_s"] is None and "damage" not in c["truth"]


def test_healthy_stories_and_masses_within_tolerance(design):
    _, _, cases = design
    for c in cases:
        assert len(c["healthy"]) == 10 and all(abs(h - 1) <= 0.03 for h in c["healthy"])
        assert all(abs(m / m0 - 1) <= 0.02 for m, m0 in zip(c["masses"], cc.TABLE1_MASS_T))
        frame = c["truth"]["frame"]
        masses = [m / 1e3 for m in frame["masses_kg"]]
        if c["family"] == "stuck":  # the jammed sphere's mass on the top floor
            assert c["truth"]["device"]["kind"] == "none"
            masses[-1] -= cc.SPHERE_T
        assert all(abs(a - b) < 1e-9 for a, b in zip(masses, c["masses"]))
        expect = [h * (1 - c["loss"] if c["family"] == "before" and i + 1 in c["damaged"] else 1)
                  for i, h in enumerate(c["healthy"])]
        assert all(abs(a - b) < 1e-12 for a, b in zip(frame["stiffness_scales"], expect))
        if "vines" in c["truth"]:
            assert abs(c["truth"]["vines"]["eps"] / 0.7 - 1) <= 0.02


def test_every_story_and_loss_covered(design):
    quick, recs, cases = design
    during = [c for c in cases if c["family"] == "during"]
    for device in (None,) if quick else cc.DEVICES:
        cells = {(c["damaged"][0], c["loss"]) for c in during if device is None or c["device"] == device}
        assert cells == {(s, l) for s in range(1, 11) for l in cc.LOSSES}, device
    assert {c["device"] for c in during} == set(cc.DEVICES)
    assert {c["record"] for c in during} == {r["path"] for r in recs}  # spread over every record
    if not quick:
        per = {}
        for c in during:
            per[c["record"]] = per.get(c["record"], 0) + 1
        assert max(per.values()) - min(per.values()) <= len(cc.DEVICES)  # evenly
        assert sum(c["family"] == "undamaged" for c in cases) >= 300
        assert {c["damaged"][0] for c in cases if c["family"] == "before"} == set(range(1, 11))
        assert any(c["family"] == "stuck" for c in cases) and any(c["family"] == "two during" for c in cases)


def test_deterministic_for_a_seed(design):
    quick, recs, cases = design
    strip = lambda cs: json.dumps(cs, sort_keys=True)
    assert strip(cc.cases(recs, quick=quick, seed=11)) == strip(cases)
    assert strip(cc.cases(recs, quick=quick, seed=12)) != strip(cases)


def test_duration_rule_and_sct_separate(design):
    _, recs, cases = design
    assert cc.run_duration(20.0, 100.0) == 40.0
    assert cc.run_duration(76.5, 163.4) == 86.5
    assert cc.run_duration(9.5, 19.9) == 19.9  # no longer than the record
    for c in cases:
        r = next(r for r in recs if r["path"] == c["record"])
        assert c["duration_s"] == min(max(40.0, r["t95"] + 10.0), r["length_s"])
        assert c["sct"] == ("_SCT_" in c["record"])
    rows = ct.rows([dict(case=c, twin=dict(detected=False), steps=1, wall=0.0) for c in cases])
    assert {r[0] for r in rows} == {"9 records", "SCT", "every record"}
    assert sum(int(r[3]) for r in rows if r[0] == "every record" and r[1] != "all") == len(cases)
    for r in rows:
        if r[0] == "SCT":
            assert int(r[3]) == sum(c["sct"] and c["device"] == {"bare": "none", "TMD": "tmd", "VI NES": "vines"}[r[1]]
                                    and c["label"] == r[2] for c in cases)


def test_arias_times():
    acc = [0.0] * 100 + [1.0] * 100 + [0.0] * 100  # dt 0.01: energy evenly over 1-2 s
    t05, t25, t75, t95 = cc.arias_times(acc, 0.01)
    assert abs(t05 - 1.04) < 0.011 and abs(t25 - 1.24) < 0.011 and abs(t75 - 1.74) < 0.011 and abs(t95 - 1.94) < 0.011


@pytest.mark.skipif(not HAVE_RECORDS, reason=f"the ground motions are not in {RECORDS_DIR}")
def test_real_records():
    sct = cc.record_info(os.path.join(RECORDS_DIR, "mexico_1985_michoacan_SCT_time_ns_ew_v_g.txt"))
    assert 39 < sct["t05"] < 40.5 and 76 < sct["t95"] < 77 and abs(sct["duration_s"] - sct["t95"] - 10) < 1e-9
    assert sct["sct"]
    if cc._vines_package(VINES) is not None:  # the plain reader as the program's reader
        for name, keys in cc.RECORDS.items():
            path = os.path.join(RECORDS_DIR, name)
            a, dt = cc.read_record_plain(path, **keys)
            b, dt2 = cc.read_record(path, VINES)
            assert len(a) == len(b) and abs(dt - dt2) < 1e-12, name
            assert max(abs(x - y) for x, y in zip(a, b)) < 1e-9 * max(map(abs, b)), name


def wilson_by_root(k, n, z=1.959963984540054):
    """The Wilson interval from its definition: the p whose score |k/n - p| / sqrt(p(1-p)/n) is z."""
    f = lambda p: (k / n - p) ** 2 - z * z * p * (1 - p) / n
    def root(a, b):
        for _ in range(200):
            m = (a + b) / 2
            a, b = (m, b) if (f(a) > 0) == (f(m) > 0) else (a, m)
        return (a + b) / 2
    p = k / n
    return (0.0 if k == 0 else root(0.0, p)), (1.0 if k == n else root(p, 1.0))


def test_wilson_interval():
    for k, n in [(0, 300), (3, 300), (1, 30), (15, 20), (20, 20), (50, 100)]:
        lo, hi = ct.wilson(k, n)
        rlo, rhi = wilson_by_root(k, n)
        assert abs(lo - rlo) < 1e-9 and abs(hi - rhi) < 1e-9, (k, n)
    lo, hi = ct.wilson(0, 300)
    assert abs(lo) < 1e-12 and abs(hi - 0.01263) < 1e-4  # 0 of 300: at most 1.26 %


def synthetic(family, loss, damaged, twin, device="none", sct=False, onset=20.0):
    case = dict(family=family, label=f"{family} {loss}", device=device, record="/r/x.at2", sct=sct, damaged=damaged,
                loss=loss, onset_s=onset if family.endswith("during") else None, seed=1, healthy=[1] * 10)
    return dict(case=case, twin=twin, steps=1000, wall=0.05)


def test_table_arithmetic():
    res = []
    # 10 % during: 20 runs; 17 right within 20 s (size off by 1, onset off by 1 s), 1 right but 25 s
    # late, 1 the wrong story, 1 missed; one more run failed.
    for i in range(17):
        res.append(synthetic("during", 0.10, [4], dict(detected=True, stories=[4], sizes=[0.11], story=4, size=0.11,
                                                    detect_time_s=25.0, onset_s=21.0, story_identified=True)))
    res.append(synthetic("during", 0.10, [4], dict(detected=True, stories=[4], sizes=[0.125], detect_time_s=45.5,
                                                onset_s=40.0)))
    res.append(synthetic("during", 0.10, [4], dict(detected=True, stories=[5], sizes=[0.1], detect_time_s=24.0,
                                                onset_s=20.5)))
    res.append(synthetic("during", 0.10, [4], dict(detected=False, stories=[], sizes=[], onset_s=None)))
    res.append(dict(case=res[0]["case"], error="boom"))
    # an old report (story, size; no onset): located, size 3 points off
    old = synthetic("before", 0.05, [2], dict(detected=True, story=2, size=0.08, detect_delay_s=3.0))
    res.append(old)
    # undamaged: 300 runs, 2 alarms; "story not identified" is no location
    res += [synthetic("undamaged", 0.0, [], dict(detected=i < 2)) for i in range(300)]
    res.append(synthetic("before", 0.05, [2], dict(detected=True, stories=[2], story_identified=False)))
    # two stories: both named; a report that names one story alone: one of them
    res.append(synthetic("two during", 0.10, [3, 7], dict(detected=True, stories=[3, 7], detect_time_s=30.0)))
    res.append(synthetic("two during", 0.10, [3, 7], dict(detected=True, stories=[3], detect_time_s=30.0)))
    res.append(synthetic("two during", 0.10, [3, 7], dict(detected=True, story=7, detect_time_s=30.0)))
    rows = {(r[1], r[2]): dict(zip(ct.HEAD, r)) for r in ct.rows(res)}
    assert rows[("bare", "two during 0.1")]["located"].startswith(" 66.7 %")
    d = rows[("bare", "during 0.1")]
    assert d["runs"] == "21" and d["failed"] == "1"
    assert d["detected"].startswith(" 95.0 %")                     # 19/20
    assert d["located"].startswith(" 90.0 %")                      # 18/20
    assert d["located <=20 s"].startswith(" 85.0 % (>=95 ✗)")      # 17/20 (one 25.5 s late)
    assert d["size within"].startswith(" 85.0 % (>=95 ✗) <=2 pt")  # 17/20 within 2 points
    assert d["size err pt mean/p90"] == "%.2f / 1.00" % ((17 * 1.0 + 2.5) / 18)
    assert d["onset err s mean/p90"] == "%.1f / 1.0" % ((17 + 20 + 0.5) / 19)
    assert d["onset within 2 s"].startswith(" 90.0 %")             # 18/20 (the 20 s error, the miss)
    b = rows[("bare", "before 0.05")]
    assert b["located"].startswith(" 50.0 %") and b["size err pt mean/p90"] == "3.00 / 3.00"
    u = rows[("all", "undamaged")]
    lo, hi = ct.wilson(2, 300)
    assert u["false alarms [95 % CI]"] == f"2/300 = 0.7 % [{100 * lo:.1f}, {100 * hi:.1f}] (<=1 ✓)"
    res += [synthetic("undamaged", 0.0, [], dict(detected=True))] * 2
    u = {(r[1], r[2]): dict(zip(ct.HEAD, r)) for r in ct.rows(res)}[("all", "undamaged")]
    assert u["false alarms [95 % CI]"].startswith("4/302 = 1.3 %") and u["false alarms [95 % CI]"].endswith("✗)")


def test_device_health():
    dev = lambda **d: dict(detected=False, device=d)
    res = [synthetic("undamaged", 0.0, [], dev(sphere="moving", impulse_truth_ns=100.0, impulse_estimated_ns=e),
                     device="vines") for e in (80.0, 124.0, 126.0, 70.0)]
    res += [synthetic("stuck", 0.0, [], dev(sphere=s, impulse_truth_ns=0.0, impulse_estimated_ns=5.0), device="vines")
            for s in ("stuck", "stuck", "still")]
    h = {r[0]: r for r in ct.health(res)}
    assert h["impulse within 25 %"][2].startswith("2/4 = 50.0 %") and h["impulse within 25 %"][2].endswith("✗)")
    assert h["stuck reported"][2].startswith("2/3 = 66.7 %")
    assert h["stuck on a moving sphere"][2].startswith("0/4 = 0.0 %") and h["stuck on a moving sphere"][2].endswith("✓)")


@pytest.mark.parametrize("quick", [False, True], ids=["default", "quick"])
def test_commissioned_buildings(quick):
    """Each device's buildings are commissioned on the three other earthquakes, each run adding to
    its own baseline; their tests leave those records out, run every other record undamaged,
    and lose each story (quick: 3 and 8) 5 and 10 % before the record, from the baseline, on
    that building as it was commissioned."""
    recs = fake_records()
    n = 1 if quick else 3
    with tempfile.TemporaryDirectory() as tmp:
        bs = cb.drawn(recs, tmp, buildings=n, seed=11, seeds=5)
        cases = cb.cases(bs, recs, quick=quick, seed=11, seeds=5, fail=pytest.fail)
    assert len(bs) == n * len(cc.DEVICES) and len({b["baseline"] for b in bs}) == len(bs)
    by = {b["baseline"]: b for b in bs}
    for b in bs:
        assert [os.path.basename(c["record"]) for c in b["commission"]] == list(cb.COMMISSION_RECORDS)
        assert all(c["commission"] == b["baseline"] and not c["baseline"] and not c["damaged"] for c in b["commission"])
        assert all(c["truth"]["frame"] == b["truth"]["frame"] for c in b["commission"])
    for c in cases:
        b = by[c["baseline"]]
        assert c["device"] == b["device"] and os.path.basename(c["record"]) not in cb.COMMISSION_RECORDS
        healthy = b["truth"]["frame"]["stiffness_scales"]
        want = [x * (1 - c["loss"] if i + 1 in c["damaged"] else 1) for i, x in enumerate(healthy)]
        assert c["truth"]["frame"]["stiffness_scales"] == pytest.approx(want)
        assert c["truth"]["frame"]["masses_kg"] == b["truth"]["frame"]["masses_kg"] and "damage" not in c["truth"]
    quiet = [c for c in cases if c["family"] == "undamaged baseline"]
    assert len(quiet) == len(bs) * (len(recs) - len(cb.COMMISSION_RECORDS))
    for device in cc.DEVICES:
        lost = sorted((c["damaged"][0], c["loss"]) for c in cases if c["family"] == "before baseline" and c["device"] == device)
        stories = (3, 8) if quick else range(1, 11)
        assert lost == sorted((s, loss) for s in stories for loss in cb.LOSSES for _ in range(1 if quick else 2))


def test_limit_keeps_every_family(design):
    _, _, cases = design
    families = list(dict.fromkeys(c["family"] for c in cases))
    few = tb.limited(cases, len(families))
    assert [c["family"] for c in few] == families


def tool(*args, **kw):
    return subprocess.run([sys.executable, os.path.join(SOURCE, "tools", "twin_benchmark.py"), *args],
                          capture_output=True, text=True, **kw)


def test_missing_inputs_exit_2():
    p = tool("--vines", "/no/such/vines")
    assert p.returncode == 2 and "/no/such/vines" in p.stderr
    exe = sys.executable  # any executable passes the program's check
    p = tool("--vines", exe, "--records", "/no/such/folder")
    assert p.returncode == 2 and "/no/such/folder" in p.stderr
    with tempfile.TemporaryDirectory() as d:
        p = tool("--vines", exe, "--records", d)
        assert p.returncode == 2 and next(iter(cc.RECORDS)) in p.stderr
        if HAVE_RECORDS:
            p = tool("--vines", exe, "--records", RECORDS_DIR, "--baseline-dir", d)
            assert p.returncode == 2 and os.path.join(d, "none.toml") in p.stderr
            p = tool("--vines", exe, "--records", RECORDS_DIR, "--commission", "-1")
            assert p.returncode == 2 and "--commission -1" in p.stderr


@pytest.mark.skipif(not (os.access(VINES, os.X_OK) and HAVE_RECORDS),
                    reason=f"needs the program ({VINES}) and the ground motions ({RECORDS_DIR})")
def test_devices_chosen():
    def planned(*args):
        p = tool("--vines", VINES, "--records", RECORDS_DIR, "--only", "during", "--plan", *args)
        assert p.returncode == 0, p.stderr
        return int(p.stderr.split("planned ")[1].split()[0])
    every = planned()
    assert planned("--devices", "vines") * 3 == every  # each device has as many runs during the record
    assert planned("--devices", "none,tmd") * 3 == every * 2
    p = tool("--vines", VINES, "--records", RECORDS_DIR, "--devices", "vinez", "--plan")
    assert p.returncode == 2 and "--devices vinez: not a device" in p.stderr


@pytest.mark.skipif(not (os.access(VINES, os.X_OK) and HAVE_RECORDS),
                    reason=f"needs the program ({VINES}) and the ground motions ({RECORDS_DIR})")
def test_tiny_real_run():
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "runs.json")
        p = tool("--vines", VINES, "--records", RECORDS_DIR, "--quick", "--only", "undamaged,before,during",
                 "--limit", "3", "--duration", "6", "--jobs", "2", "--json", out, timeout=600)
        print(p.stdout, p.stderr)
        assert p.returncode in (0, 1), p.stderr
        assert "planned 3 runs" in p.stderr
        runs = json.load(open(out))
        assert len(runs) == 3 and {r["family"] for r in runs} == {"undamaged", "before", "during"}
        for r in runs:  # every run counted: a report, or an error that the table lists
            assert (r["twin"] is None) != (r["error"] is None)
            if r["family"] != "during":  # no [damage] table: any program since issue 31 runs them
                assert r["twin"] is not None and "detected" in r["twin"], r["error"]
        assert "| every record | all" in p.stdout and "device health" in p.stdout
        failed = sum(r["error"] is not None for r in runs)
        assert (f"failed runs: {failed}" in p.stdout) == (failed > 0)


def test_calibration_holds_the_statistic(tmp_path):
    """tools/twin_calibrate.py: the largest one-story statistic held for 2 s (40 updates of
    50 samples), not a one-update spike; its story."""
    import twin_calibrate
    path = tmp_path / "run.csv"
    names = [f"stat_{j}" for j in range(1, 11)]
    with open(path, "w") as f:
        f.write(",".join(["k"] + names) + "\n")
        for update in range(200):
            stat = [0.5] * 10
            if update == 10:
                stat[1] = 100.0  # a spike: not held
            if 50 <= update < 120:
                stat[3] = 30.0 + (update == 80)  # held 3.5 s: 30
            for k in range(50):
                f.write(",".join([str(50 * update + k)] + [repr(v) for v in stat]) + "\n")
    held, story = twin_calibrate.held_max(str(path))
    assert held == 30.0 and story == 4


if __name__ == "__main__":
    if len(sys.argv) > 1:
        os.environ["VINES_SOURCE_DIR"] = sys.argv[1]
    if len(sys.argv) > 2:
        os.environ["VINES_EXE"] = sys.argv[2]
    sys.exit(pytest.main([os.path.abspath(__file__), "-q", "-p", "no:cacheprovider", "-rs"]))
