#!/usr/bin/env python3
"""What any twin estimator could do: the information bound of the damage campaign.

For the bare shear frame fed a record, sensed by floor accelerometers with white noise, this
computes the Fisher information of the stories' stiffness factors and the floors' masses, and
from it (docs/twin.md section 7):
- the Cramer-Rao bound of each story's stiffness factor with the masses known;
- the Bayesian (van Trees) bound with the masses unknown within +-P % (a Gaussian prior of the
  uniform's sd): no estimator's rms error can be smaller;
- the bias of an estimator that keeps the nominal masses (the linearised best fit of the
  stiffnesses to a truth whose masses are off): its sd per story;
- the campaign's figures of the marginal-threshold rule: estimates that err exactly by the
  Bayesian bound, each story's alarm above max(z sd, floor), the best rule whose false alarms
  stay within 1 %;
- the campaign's figures of the one-story GLRT, the best detector of the hypothesis the campaign
  poses (tools/twin_glrt.py): masses unknown; nominal masses with and without the bias in the
  whitening; healthy stories off their nominal by up to H % with the change measured during the
  record (the part before an onset in the Arias 25-75 % span as the baseline), against a
  baseline from the other records, or without a baseline.
Each record runs for max(--duration, its Arias 95 % time + 10 s), or to its end.
With --device vines the frame carries the campaign's VI NES, its sphere starting at --sphere-x0:
every impact's force is left unknown (tools/twin_bound_vines.py), and the noise is 5 % of each
channel's RMS with the impacts' spikes in it, as the campaign draws it.

Usage: twin_bound.py [--records DIR] [--sensors 3,6,8,10] [--noise-pct 5] [--mass-pct 2]
                     [--healthy-pct 3] [--duration 40] [--skip SUBSTRING ...] [--draws 400]
                     [--false-alarm 1] [--glrt-draws 300] [--onsets 5] [--node-json FILE] [--quick]
                     [--device none|vines] [--sphere-x0 M]
Needs numpy and the vines Python package (build/release/python, or PYTHONPATH) to read records;
--device vines also scipy.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import twin_bound_vines as tv  # noqa: E402
import twin_campaign_cases as cc  # noqa: E402
import twin_glrt as glrt  # noqa: E402
from twin_benchmark import RECORDS, TABLE1_K_MN, TABLE1_MASS_T  # noqa: E402

DAMPING_S = 0.0129  # C = 0.0129 s * K (docs/model.md)


def state_space(k, m, sensors):
    """The shear frame (story stiffnesses k, floor masses m, C = DAMPING_S K) as
    x' = A x + b ag, y = C x: x the floors' displacements then velocities relative to the
    ground, y the absolute accelerations of the floors `sensors` (1-based)."""
    n = len(m)
    K = np.diag(k + np.append(k[1:], 0.0)) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    Minv = np.diag(1.0 / m)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -DAMPING_S * Minv @ K]])
    b = np.concatenate([np.zeros(n), -np.ones(n)])
    C = (-Minv @ np.hstack([K, DAMPING_S * K]))[np.asarray(sensors) - 1]
    return A, b, C


def outputs(k, m, ag, h, sensors, imp=None):
    """The sensors' outputs (state_space) from rest at t = 0, under the ground acceleration
    ag sampled every h (held over each step) and, with imp, a force on the top floor whose
    impulse over step i is imp[i] (applied at the step's middle; the force's own share of the
    top floor's acceleration at a sample is not in the outputs): array (len(ag), len(sensors))."""
    A, b, C = state_space(k, m, sensors)
    lam, V = np.linalg.eig(A)
    n = len(m)
    gain = (np.exp(lam * h) - 1) / lam * np.linalg.solve(V, b)
    cv = C @ V
    # Each mode: z[i+1] = exp(lam h) z[i] + gain ag[i] (+ its share of imp[i]), by FFT convolution.
    T = len(ag)
    L = 1 << int(np.ceil(np.log2(2 * T)))
    decay = np.exp(np.outer(lam * h, np.arange(T)))
    fd = np.fft.fft(decay, L)
    z = np.fft.ifft(fd * np.fft.fft(ag, L), L)[:, :T] * gain[:, None]
    if imp is not None:
        top = np.zeros(2 * n)
        top[2 * n - 1] = 1.0 / m[-1]
        z += np.fft.ifft(fd * np.fft.fft(imp, L), L)[:, :T] * (np.exp(lam * h / 2) * np.linalg.solve(V, top))[:, None]
    z = np.hstack([np.zeros((len(lam), 1)), z[:, :-1]])
    return (cv @ z).real.T


def jacobian(k, m, ag, h, sensors, noise_pct, imp=None, sd=None):
    """The outputs' sensitivities to (log k, log m), each channel divided by its white noise's
    sd (noise_pct % of its rms, or sd given): array (2 n, samples, sensors); central differences
    of the outputs (the model is linear in its state, smooth in its parameters)."""
    if sd is None:
        y0 = outputs(k, m, ag, h, sensors, imp)
        sd = noise_pct / 100 * np.sqrt((y0 ** 2).mean(axis=0))
    n, step = len(k), 1e-5
    jac = []
    for j in range(2 * n):
        e = np.zeros(2 * n)
        e[j] = step
        up = outputs(k * np.exp(e[:n]), m * np.exp(e[n:]), ag, h, sensors, imp)
        dn = outputs(k * np.exp(-e[:n]), m * np.exp(-e[n:]), ag, h, sensors, imp)
        jac.append((up - dn) / (2 * step) / sd)
    return np.array(jac)


def fisher(k, m, ag, h, sensors, noise_pct):
    """Fisher information of (log k, log m) from the sensors' samples (jacobian())."""
    jac = jacobian(k, m, ag, h, sensors, noise_pct).reshape(2 * len(k), -1)
    return jac @ jac.T


def bounds(F, mass_sd):
    """(sd with masses known, Bayesian bound's covariance with the mass prior, sd of the
    nominal-mass estimator's bias): the stiffness factors', relative (0.01 = 1 %)."""
    n = len(F) // 2
    Fkk, Fkm = F[:n, :n], F[:n, n:]
    known = np.sqrt(np.diag(np.linalg.inv(Fkk)))
    prior = np.zeros_like(F)
    prior[n:, n:] = np.eye(n) / mass_sd ** 2
    cov = np.linalg.inv(F + prior)[:n, :n]
    G = np.linalg.solve(Fkk, Fkm)
    bias = np.sqrt(np.diag(G @ G.T)) * mass_sd
    return known, cov, bias


def ideal_detector(covs, draws, seed=1):
    """The campaign's figures of a detector whose loss estimates err as N(0, cov) on each
    record: alarm on a story whose loss exceeds max(z sd, floor); reported story the largest
    loss over its threshold. Returns the rule (z, floor) of the best 5 % and 10 % figures whose
    false alarms stay within 1 %, with (false alarms, 5 % located, 5 % located and size within
    1.5 points, 10 % located, 10 % located and size within 2 points), in %."""
    rng = np.random.default_rng(seed)
    factors = [(np.linalg.cholesky(cov * 1e4), np.sqrt(np.diag(cov * 1e4))) for cov in covs]  # points
    best = None
    for z in (2.0, 2.5, 3.0, 3.5, 4.0):
        for floor in (1.0, 2.0, 3.0, 4.0):
            hits = np.zeros(5)
            runs = 0
            for L, sd in factors:
                thr = np.maximum(z * sd, floor)
                for _ in range(draws):
                    e = L @ rng.standard_normal(len(thr))
                    story = rng.integers(len(thr))
                    hits[0] += np.any(e > thr)
                    for col, loss, tol in ((1, 5.0, 1.5), (3, 10.0, 2.0)):
                        est = e.copy()
                        est[story] += loss
                        located = np.any(est > thr) and np.argmax(est / thr) == story
                        hits[col] += located
                        hits[col + 1] += located and abs(est[story] - loss) <= tol
                    runs += 1
            row = 100 * hits / runs
            if row[0] <= 1 and (best is None or row[2] + row[4] > best[1][2] + best[1][4]):
                best = ((z, floor), row)
    return best


def bare_information(vines, path, k, m, ag, h, sensors, args, cuts):
    """The bare frame's Fisher information of (log k, log m) over the run, and over the samples
    before each of cuts (vines and path unused: vines_information's signature)."""
    jac = jacobian(k, m, ag, h, sensors, args.noise_pct)
    return np.einsum("itc,jtc->ij", jac, jac), [np.einsum("itc,jtc->ij", jac[:, :i], jac[:, :i]) for i in cuts]


def vines_information(vines, path, k, m, ag, h, sensors, args, cuts):
    """The same for the campaign's VI NES building, every impact's force unknown
    (twin_bound_vines.py); the run ends where the truth's does, if sooner."""
    imp, kicked, touched, acc = tv.impacts(vines, cc.building("vines", path, x0=args.sphere_x0), h, len(ag) * h)
    T = min(len(ag), len(imp))
    rows = np.array(sensors) - 1
    sd = args.noise_pct / 100 * np.sqrt((acc[:T, rows] ** 2).mean(axis=0))
    jac = jacobian(k, m, ag[:T], h, sensors, args.noise_pct, imp=imp[:T], sd=sd)
    A, _, C = state_space(k, m, sensors)
    top = sensors.index(len(k)) if len(k) in sensors else None
    return tv.information(jac, A, C, sd, kicked[:T], touched[:T], top, h, cuts)


def run_length(rec, duration, h):
    """(ground acceleration every h over the run, Arias 25 % and 75 % times): the run lasts
    max(duration, the Arias 95 % time + 10 s), or to the record's end if that is sooner (the
    node's run stops there too); Arias intensity over the whole record."""
    arias = np.cumsum(rec.acc ** 2)
    arias /= arias[-1]
    at = lambda p: rec.t[np.searchsorted(arias, p)]
    t = np.arange(0.0, min(max(duration, at(0.95) + 10.0), rec.t[-1]), h)
    return np.interp(t, rec.t, rec.acc), at(0.25), at(0.75)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--records", default=os.path.join(ROOT, "..", "shared", "data", "ground_motions"))
    ap.add_argument("--sensors", default="3,6,8,10")
    ap.add_argument("--noise-pct", type=float, default=5.0)
    ap.add_argument("--mass-pct", type=float, default=2.0, help="masses off by up to this, uniformly")
    ap.add_argument("--healthy-pct", type=float, default=3.0,
                    help="healthy stories' stiffness off by up to this, uniformly (section 3 of the GLRT)")
    ap.add_argument("--duration", type=float, default=40.0, help="at least this long, else Arias 95 %% + 10 s")
    ap.add_argument("--rate", type=float, default=1000.0, help="sensor rate [Hz]")
    ap.add_argument("--skip", nargs="*", default=[], help="leave out records whose name holds one of these")
    ap.add_argument("--draws", type=int, default=400, help="ideal detector's draws per record")
    ap.add_argument("--false-alarm", type=float, default=1.0, help="the GLRT's false alarms [%%]")
    ap.add_argument("--glrt-draws", type=int, default=300, help="GLRT draws per record, story and loss")
    ap.add_argument("--onsets", type=int, default=5, help="onsets in the Arias 25-75 %% span (during the record)")
    ap.add_argument("--node-json", help="a tools/twin_benchmark.py --json file: the node's size errors against "
                    "the bound's")
    ap.add_argument("--quick", action="store_true", help="fewer draws and onsets (a minute less, figures rougher)")
    ap.add_argument("--device", choices=("none", "vines"), default="none",
                    help="the frame bare, or with the campaign's VI NES and every impact's force unknown")
    ap.add_argument("--sphere-x0", type=float, default=0.2, help="--device vines: the sphere's start [m]")
    args = ap.parse_args()
    if args.quick:
        args.draws, args.glrt_draws, args.onsets = 100, 60, 2
    try:
        sensors = [int(s) for s in args.sensors.split(",")]
    except ValueError:
        sys.exit(f"twin_bound.py: error: --sensors {args.sensors}: floors 1-10, comma separated")
    if not all(1 <= s <= 10 for s in sensors) or len(set(sensors)) != len(sensors):
        sys.exit(f"twin_bound.py: error: --sensors {args.sensors}: floors 1-10, each once")
    for name, v, lo in (("--noise-pct", args.noise_pct, 0), ("--mass-pct", args.mass_pct, 0),
                        ("--duration", args.duration, 0), ("--rate", args.rate, 0), ("--draws", args.draws, 0),
                        ("--healthy-pct", args.healthy_pct, 0), ("--false-alarm", args.false_alarm, 0),
                        ("--glrt-draws", args.glrt_draws, 0), ("--onsets", args.onsets, 0)):
        if not (np.isfinite(v) and v > lo):
            sys.exit(f"twin_bound.py: error: {name} {v}: must be a positive number")
    if args.device == "vines" and not (np.isfinite(args.sphere_x0) and abs(args.sphere_x0) < cc.GAP_M):
        sys.exit(f"twin_bound.py: error: --sphere-x0 {args.sphere_x0}: within the box's +-{cc.GAP_M} m")
    if args.false_alarm >= 100:
        sys.exit(f"twin_bound.py: error: --false-alarm {args.false_alarm}: a percentage under 100")
    nodes = None
    if args.node_json:
        try:
            nodes = glrt.node_size_errors(args.node_json)
        except (OSError, ValueError, KeyError, TypeError) as e:
            sys.exit(f"twin_bound.py: error: --node-json {args.node_json}: {e}")
    try:
        sys.path.insert(0, os.path.join(ROOT, "build", "release", "python"))
        import vines
    except ImportError:
        sys.exit("twin_bound.py: error: the vines Python package is not built (cmake --build --preset release)")
    if not os.path.isdir(args.records):
        sys.exit(f"twin_bound.py: error: --records {args.records}: no such folder")

    k = np.array(TABLE1_K_MN) * 1e6
    m = np.array(TABLE1_MASS_T) * 1e3
    h = 1.0 / args.rate
    mass_sd = args.mass_pct / 100 / np.sqrt(3)
    frame = "bare Table 1 frame" if args.device == "none" else \
        f"Table 1 frame with the campaign's VI NES (sphere from {args.sphere_x0:g} m, every impact unknown)"
    print(f"twin bound: {frame}, floors {args.sensors} at {args.rate:g} Hz, noise {args.noise_pct:g} % rms, "
          f"masses within +-{args.mass_pct:g} %, each record for max({args.duration:g} s, Arias 95 % + 10 s) "
          "or to its end")
    print("record | run s | sd, masses known (largest) | Bayesian bound, masses unknown (median / largest) "
          "| nominal-mass estimator's bias sd (median / largest)")
    covs, info = [], {}
    for name in sorted(RECORDS):
        if any(s in name for s in args.skip):
            continue
        path = os.path.join(args.records, name)
        try:
            rec = vines.Record.load(path, **RECORDS[name])
        except Exception as e:  # the package's RecordError names the file and the reason
            sys.exit(f"twin_bound.py: error: {e}")
        ag, t25, t75 = run_length(rec, args.duration, h)
        cuts = [int(round((t25 + q * (t75 - t25)) / h))  # onsets spread evenly over the span
                for q in (np.arange(args.onsets) + 0.5) / args.onsets]
        F, befores = (bare_information if args.device == "none" else vines_information)(
            vines, path, k, m, ag, h, sensors, args, cuts)
        parts = [(before, F - before) for before in befores]
        info[name] = (F, parts)
        known, cov, bias = bounds(F, mass_sd)
        bayes = np.sqrt(np.diag(cov))
        covs.append(cov)
        print(f"{name[:44]:44s} | {len(ag) * h:5.1f} | {100 * known.max():5.2f} % | {100 * np.median(bayes):5.2f} / "
              f"{100 * bayes.max():5.2f} % | {100 * np.median(bias):5.2f} / {100 * bias.max():5.2f} %", flush=True)
    if not info:
        sys.exit("twin_bound.py: error: --skip left no record")
    (z, floor), row = ideal_detector(covs, args.draws)
    print(f"marginal-threshold rule (errors at the Bayesian bound; alarm above max({z:g} sd, {floor:g} %)): "
          f"false alarms {row[0]:.1f} %; 5 % loss located {row[1]:.1f} %, size within 1.5 points {row[2]:.1f} %; "
          f"10 % loss located {row[3]:.1f} %, size within 2 points {row[4]:.1f} %")
    glrt.report(info, args.mass_pct / 100, args.healthy_pct / 100, args.false_alarm / 100, args.glrt_draws, nodes)


if __name__ == "__main__":
    main()
