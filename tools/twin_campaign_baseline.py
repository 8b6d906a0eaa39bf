"""The twin campaign's commissioned buildings (tools/twin_benchmark.py, docs/twin.md section 5,
issue 52): what a monitoring team does when it installs the system. Per device, buildings drawn
as the campaign's healthy truths are commissioned (`vines hil --commission`) on healthy records
of other earthquakes (COMMISSION_RECORDS); the node then runs from that baseline
(`--baseline`) on the remaining records, undamaged and with a story lost before the record.

A building is a dict: device, truth (scene tables of the healthy building), baseline (the
file), used (record names it was commissioned on), commission (the commissioning runs, cases
for twin_benchmark.run; empty when the baseline came from --baseline-dir)."""
import json
import os
import random
import tomllib

import twin_campaign_cases as cc

# Three earthquakes the tests then leave out: Taft 1952, Kobe 1995, Loma Prieta 1989.
COMMISSION_RECORDS = ("taft_1952_kern_county_TAF021_nga_west2_rsn15.at2",
                      "kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2",
                      "lomaprieta_1989_corralitos_CLS000_nga_west2_rsn753.at2")
LOSSES = (0.05, 0.10)


def _case(family, label, b, rec, seed, damaged=(), loss=0.0):
    truth = json.loads(json.dumps(b["truth"]))
    base = truth.get("frame", {}).get("stiffness_scales", [1.0] * 10)
    if damaged:
        truth.setdefault("frame", {})["stiffness_scales"] = [
            x * (1 - loss if i + 1 in damaged else 1) for i, x in enumerate(base)]
    truth["record"] = dict({"path": rec["path"]}, **cc.RECORDS[rec["name"]])
    return dict(family=family, label=label, device=b["device"], record=rec["path"], sct=rec["sct"], truth=truth,
                damaged=list(damaged), loss=loss, onset_s=None, healthy=base, masses=b.get("masses"), seed=seed,
                duration_s=rec["duration_s"], baseline=b["baseline"])


def drawn(records, tmp, *, buildings, seed, seeds):
    """`buildings` healthy buildings per device, each with its baseline file in tmp and its
    commissioning runs (one per COMMISSION_RECORDS entry, noise seeds in turn)."""
    rng, out = random.Random(seed + 2), []
    by_name = {r["name"]: r for r in records}
    for device in cc.DEVICES:
        for k in range(buildings):
            h = cc.healthy_truth(rng)
            truth = cc.building(device, records[0]["path"], masses=h["masses"], scales=h["scales"], eps=h["eps"],
                                x0=h["x0"], tmd_x0=h["tmd_x0"])
            b = dict(device=device, truth=truth, masses=h["masses"], used=set(COMMISSION_RECORDS),
                     baseline=os.path.join(tmp, f"{device}_{k}.baseline"))
            b["commission"] = [dict(_case("commission", "commissioning", b, by_name[name], 1 + j % seeds),
                                    baseline=None, commission=b["baseline"])
                               for j, name in enumerate(COMMISSION_RECORDS)]
            out.append(b)
    return out


def from_dir(path, fail):
    """One building per device from a folder: DIR/<device>.toml (the healthy building, a truth
    scene), DIR/<device>.baseline (for `vines hil --baseline`), DIR/<device>.records (optional:
    the records it was commissioned on, one file name a line, left out of the tests)."""
    out = []
    for device in cc.DEVICES:
        paths = {e: os.path.join(path, f"{device}.{e}") for e in ("toml", "baseline", "records")}
        for e in ("toml", "baseline"):
            if not os.path.isfile(paths[e]):
                fail(f"{paths[e]}: no such file (--baseline-dir holds <device>.toml and <device>.baseline "
                     f"for the devices {', '.join(cc.DEVICES)})")
        try:
            with open(paths["toml"], "rb") as f:
                truth = tomllib.load(f)
        except (OSError, tomllib.TOMLDecodeError) as e:
            fail(f"{paths['toml']}: not a readable scene: {e}")
        used = set()
        if os.path.isfile(paths["records"]):
            used = {line.strip() for line in open(paths["records"]) if line.strip()}
        out.append(dict(device=device, truth=truth, used=used, baseline=paths["baseline"], commission=[]))
    return out


def cases(buildings, records, *, quick, seed, seeds, fail):
    """The runs from the baselines: each building undamaged on every record it was not
    commissioned on; one story lost 5 or 10 % before the record (every story twice over a
    device's buildings; quick: stories 3 and 8 once), on those records in turn."""
    rng, out = random.Random(seed + 3), []
    stories = (3, 8) if quick else tuple(range(1, 11))
    reps = 1 if quick else 2
    for device in cc.DEVICES:
        mine = [b for b in buildings if b["device"] == device]
        k = 0
        for b in mine:
            recs = [r for r in records if r["name"] not in b["used"]]
            if not recs:
                fail(f"{b['baseline']}: every record was used to commission it: none left to test on")
            for r in recs:
                out.append(_case("undamaged baseline", "undamaged, baseline", b, r, 1 + rng.randrange(seeds)))
        for loss in LOSSES:
            for s in [s for s in stories for _ in range(reps)]:
                b = mine[k % len(mine)]
                recs = [r for r in records if r["name"] not in b["used"]]
                out.append(_case("before baseline", f"loss {round(100 * loss)} % before, baseline", b,
                                 recs[(k // len(mine)) % len(recs)], 1 + rng.randrange(seeds), [s], loss))
                k += 1
    return out
