"""The one-story GLRT's bound of the damage campaign (tools/twin_bound.py, docs/twin.md section 7).

The hypothesis the campaign poses is that one story lost stiffness. Its best detector is the
generalised likelihood-ratio test (GLRT) on an estimate of the stories' log stiffness factors:
given the estimate's change th (loss coordinates: -log of the factor) and the precision W of its
error, story j's statistic and size are

    T_j = (e_j' W th)^2 / (e_j' W e_j),   delta_j = e_j' W th / (e_j' W e_j),

damage is declared when the largest T_j over the stories with delta_j > 0 (losses only) exceeds
the threshold that undamaged draws exceed in the stated share (false alarms), the story is its
argmax and the size 1 - exp(-delta_j); delta_j's sd under story j's hypothesis is
1 / sqrt(e_j' W e_j).

Every estimator here is linear in the data about the nominal frame, so its error is
A mu + noise: mu the masses' log errors (drawn uniformly within the tolerance, as the campaign
draws them), noise Gaussian with covariance Cn. `ErrorModel` holds (A, Cn) and, for the
campaigns without a baseline, the healthy stories' deviations (uniform, drawn too).
"""
import numpy as np

TOLERANCE_PT = {3.0: 1.0, 5.0: 1.5, 10.0: 2.0}  # a size counts as right within this many points


class ErrorModel:
    """An estimate's error in the stories' loss coordinates: A mu + noise (+ h), mu uniform
    within +-mass_half (log), noise N(0, Cn), h the healthy stories' deviations (-log(1 + u), u
    uniform within +-healthy_half) when the estimate carries them (no baseline); with gauss,
    h Gaussian of the same sd (half / sqrt(3)) instead."""

    def __init__(self, A, Cn, mass_half, healthy_half=0.0, gauss=False):
        self.A, self.Cn, self.mass_half, self.healthy_half, self.gauss = A, Cn, mass_half, healthy_half, gauss
        self.Ln = np.linalg.cholesky(Cn)

    def cov(self):
        """The error's covariance (the uniforms' variance half^2 / 3)."""
        n = len(self.Cn)
        return (self.Cn + self.A @ self.A.T * self.mass_half ** 2 / 3
                + np.eye(n) * self.healthy_half ** 2 / 3)

    def draw(self, rng, count):
        n = len(self.Cn)
        mu = rng.uniform(-self.mass_half, self.mass_half, (self.A.shape[1], count))
        e = self.A @ mu + self.Ln @ rng.standard_normal((n, count))
        if self.healthy_half and self.gauss:
            e += self.healthy_half / np.sqrt(3) * rng.standard_normal((n, count))
        elif self.healthy_half:
            e += -np.log1p(rng.uniform(-self.healthy_half, self.healthy_half, (n, count)))
        return e


def with_masses_unknown(F, mass_half):
    """The Bayesian estimate of the stiffness factors with the masses a nuisance (Gaussian
    prior of the uniform's sd): F the Fisher information of (log k, log m). Its error's k
    block is -S_km P mu + S J' n with S = (F + P)^-1; covariance S_kk."""
    n = len(F) // 2
    P = np.zeros_like(F)
    P[n:, n:] = np.eye(n) * 3 / mass_half ** 2
    S = np.linalg.inv(F + P)
    Cn = (S @ F @ S)[:n, :n]
    return -S[:n, n:] @ P[n:, n:], (Cn + Cn.T) / 2


def with_nominal_masses(F):
    """The least-squares estimate of the stiffness factors with the masses held at nominal:
    error Fkk^-1 J_k' n + Fkk^-1 Fkm mu (the bias of tools/twin_bound.py's bounds())."""
    n = len(F) // 2
    Fkk = F[:n, :n]
    return np.linalg.solve(Fkk, F[:n, n:]), np.linalg.inv(Fkk)


def change(after, before, mass_half):
    """The change between two estimates of the same building (same masses, independent noise):
    after and before are (A, Cn) pairs; the masses' errors enter through A_after - A_before."""
    return ErrorModel(after[0] - before[0], after[1] + before[1], mass_half)


def glrt(W, est):
    """(largest T over the stories with delta > 0 (0 if none), its story, the sizes delta) of
    the estimates est (stories x draws) under the error precision W."""
    X = W @ est
    d = np.diag(W)[:, None]
    delta = X / d
    T = np.where(delta > 0, X * X / d, 0.0)
    return T.max(axis=0), T.argmax(axis=0), delta


def campaign(model, W=None, false_alarm=0.01, losses=(3.0, 5.0, 10.0), draws=300, null_draws=50000, seed=1):
    """The GLRT with precision W (default: the model's own covariance inverted) on estimates that
    err as `model`: {"threshold", "false_alarm", "size_sd" (per story, points),
    loss: (located %, sized %, size-error rms of the located in points)}. The threshold is the
    (1 - false_alarm) quantile of the largest T of undamaged draws; each loss is put on every
    story `draws` times."""
    rng = np.random.default_rng(seed)
    if W is None:
        W = np.linalg.inv(model.cov())
    n = len(W)
    stat, _, _ = glrt(W, model.draw(rng, null_draws))
    thr = np.quantile(stat, 1 - false_alarm)
    out = {"threshold": thr, "size_sd": 100 / np.sqrt(np.diag(W))}
    stat, _, _ = glrt(W, model.draw(rng, null_draws))
    out["false_alarm"] = 100 * np.mean(stat > thr)
    for loss in losses:
        located = sized = 0
        sq = []
        for j in range(n):
            est = model.draw(rng, draws)
            est[j] += -np.log1p(-loss / 100)
            stat, story, delta = glrt(W, est)
            hit = (stat > thr) & (story == j)
            err = 100 * (1 - np.exp(-delta[j])) - loss
            located += hit.sum()
            sized += (hit & (np.abs(err) <= TOLERANCE_PT.get(loss, 1.5))).sum()
            sq.extend(err[hit] ** 2)
        runs = n * draws
        out[loss] = (100 * located / runs, 100 * sized / runs, float(np.sqrt(np.mean(sq))) if sq else float("nan"))
    return out


def record_campaigns(F, parts, F_others, mass_half, healthy_half, false_alarm, draws):
    """The GLRT's figures on one record (F its information, parts the (before, after)
    informations at each onset, F_others the other records' summed): {label: campaign()}."""
    out = {}
    unknown = with_masses_unknown(F, mass_half)
    out["masses unknown"] = campaign(ErrorModel(*unknown, mass_half), false_alarm=false_alarm, draws=draws)
    nominal = ErrorModel(*with_nominal_masses(F), mass_half)
    out["nominal masses, whitened"] = campaign(nominal, false_alarm=false_alarm, draws=draws)
    out["nominal masses, bias ignored"] = campaign(nominal, W=np.linalg.inv(nominal.Cn), false_alarm=false_alarm,
                                                   draws=draws)
    split = [(with_masses_unknown(after, mass_half), with_masses_unknown(before, mass_half)) for before, after in parts]
    during = [campaign(change(a, b, mass_half), false_alarm=false_alarm, draws=draws, seed=2 + i)
              for i, (a, b) in enumerate(split)]
    out["healthy off: during the record"] = {key: np.mean([d[key] for d in during], axis=0) for key in during[0]}
    # The same with each part's masses drawn on their own: the change's covariance the parts' sum.
    during = [campaign(ErrorModel(np.hstack([a[0], -b[0]]), a[1] + b[1], mass_half), false_alarm=false_alarm,
                       draws=draws, seed=2 + i) for i, (a, b) in enumerate(split)]
    out["  the same, parts' covariances summed"] = {key: np.mean([d[key] for d in during], axis=0)
                                                    for key in during[0]}
    if F_others is not None:
        out["healthy off: baseline, other records"] = campaign(
            change(unknown, with_masses_unknown(F_others, mass_half), mass_half), false_alarm=false_alarm,
            draws=draws)
    out["healthy off: no baseline"] = campaign(ErrorModel(*unknown, mass_half, healthy_half),
                                               false_alarm=false_alarm, draws=draws)
    out["  the same, Gaussian of that sd"] = campaign(ErrorModel(*unknown, mass_half, healthy_half, gauss=True),
                                                      false_alarm=false_alarm, draws=draws)
    return out


def node_size_errors(path):
    """From a tools/twin_benchmark.py --json file: {record: (runs of the bare frame with one
    story lost, their size errors in points where the story was located)}."""
    import json
    with open(path) as f:
        runs = json.load(f)
    if not isinstance(runs, list) or not all(isinstance(r, dict) for r in runs):
        raise ValueError("not a list of runs (tools/twin_benchmark.py --json writes one)")
    out = {}
    for r in runs:
        missing = [key for key in ("device", "record", "damaged", "loss") if key not in r]
        if missing:
            raise ValueError(f"a run without {', '.join(missing)} (tools/twin_benchmark.py --json writes them)")
        if r["device"] != "none" or len(r["damaged"]) != 1 or not r.get("twin"):
            continue
        count, errs = out.setdefault(r["record"], [0, []])
        out[r["record"]][0] += 1
        tw = r["twin"]
        if tw["detected"] and tw["story"] == r["damaged"][0] and tw["size"] is not None:
            errs.append(100 * (tw["size"] - r["loss"]))
    return out


def _row(label, c, losses=(3.0, 5.0, 10.0)):
    sd = c["size_sd"]
    cells = " | ".join(f"{loss:g} %: {c[loss][0]:5.1f} / {c[loss][1]:5.1f}" for loss in losses)
    return f"  {label:38s} | {np.median(sd):4.2f} / {sd.max():4.2f} % | {cells} | {c['false_alarm']:4.1f} %"


def report(info, mass_half, healthy_half, false_alarm, draws, nodes=None):
    """Prints the GLRT's figures per record, then pooled (the records but Mexico City SCT, SCT,
    all); with nodes (node_size_errors()), the node's size errors against the bound's."""
    print(f"\none-story GLRT (false alarms {100 * false_alarm:g} % by Monte Carlo; masses within "
          f"+-{100 * mass_half:g} %; healthy stories off by up to {100 * healthy_half:g} % in the last six)")
    print("  campaign                               | size sd median / largest | loss: located / sized % "
          "(within 1, 1.5, 2 points) | false alarms")
    total = sum(F for F, _ in info.values())
    results = {}
    for name, (F, parts) in info.items():
        print(name, flush=True)
        others = total - F if len(info) > 1 else None
        results[name] = record_campaigns(F, parts, others, mass_half, healthy_half, false_alarm, draws)
        for label, c in results[name].items():
            print(_row(label, c))
        if nodes is not None:
            count, errs = nodes.get(name, (0, []))
            bound = np.sqrt(np.mean(results[name]["masses unknown"]["size_sd"] ** 2))
            nominal = np.sqrt(np.mean(results[name]["nominal masses, whitened"]["size_sd"] ** 2))
            if not count:
                print("  node: the JSON file has no bare-frame one-story runs of this record")
            elif not errs:
                print(f"  node: none of its {count} one-story runs located the story")
            else:
                rms = np.sqrt(np.mean(np.square(errs)))
                print(f"  node: size error rms {rms:.2f} points over {len(errs)} located of {count} runs; bound "
                      f"{bound:.2f} (ratio {rms / bound:.1f}), nominal-mass bound {nominal:.2f} "
                      f"(ratio {rms / nominal:.1f})")
    groups = [("all records", list(results))]
    sct = [n for n in results if "mexico" in n]
    if sct and len(results) > 1:
        rest = [n for n in results if n not in sct]
        groups = [("records but Mexico City SCT", rest), ("Mexico City SCT", sct)] + groups
    for title, names in groups:
        print(f"pooled: {title} ({len(names)})")
        for label in results[names[0]]:
            cs = [results[n][label] for n in names if label in results[n]]
            pooled = {key: np.mean([c[key] for c in cs], axis=0) for key in cs[0] if key != "size_sd"}
            pooled["size_sd"] = np.concatenate([c["size_sd"] for c in cs])
            print(_row(label, pooled))
