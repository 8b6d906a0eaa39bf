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
- the campaign's figures of an ideal detector, one whose estimates err exactly by the Bayesian
  bound, with the best threshold rule whose false alarms stay within 1 %.

Usage: twin_bound.py [--records DIR] [--sensors 3,6,8,10] [--noise-pct 5] [--mass-pct 2]
                     [--duration 40] [--skip SUBSTRING ...] [--draws 400]
Needs numpy and the vines Python package (build/release/python, or PYTHONPATH) to read records.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
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


def outputs(k, m, ag, h, sensors):
    """The sensors' outputs (state_space) from rest at t = 0, under the ground acceleration
    ag sampled every h (held over each step): array (len(ag), len(sensors))."""
    A, b, C = state_space(k, m, sensors)
    lam, V = np.linalg.eig(A)
    b = np.linalg.solve(V, b)
    cv = C @ V
    # Each mode: z[i+1] = exp(lam h) z[i] + (exp(lam h) - 1) / lam b ag[i], by FFT convolution.
    T = len(ag)
    L = 1 << int(np.ceil(np.log2(2 * T)))
    decay = np.exp(np.outer(lam * h, np.arange(T)))
    gain = (np.exp(lam * h) - 1) / lam * b
    z = np.fft.ifft(np.fft.fft(decay, L) * np.fft.fft(ag, L), L)[:, :T] * gain[:, None]
    z = np.hstack([np.zeros((len(lam), 1)), z[:, :-1]])
    return (cv @ z).real.T


def fisher(k, m, ag, h, sensors, noise_pct):
    """Fisher information of (log k, log m) from the sensors' samples, each channel's white
    noise noise_pct % of its rms; central differences of the outputs (the model is linear in
    its state, smooth in its parameters)."""
    y0 = outputs(k, m, ag, h, sensors)
    sd = noise_pct / 100 * np.sqrt((y0 ** 2).mean(axis=0))
    n, step = len(k), 1e-5
    jac = []
    for j in range(2 * n):
        e = np.zeros(2 * n)
        e[j] = step
        up = outputs(k * np.exp(e[:n]), m * np.exp(e[n:]), ag, h, sensors)
        dn = outputs(k * np.exp(-e[:n]), m * np.exp(-e[n:]), ag, h, sensors)
        jac.append(((up - dn) / (2 * step) / sd).ravel())
    jac = np.array(jac)
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--records", default=os.path.join(ROOT, "..", "shared", "data", "ground_motions"))
    ap.add_argument("--sensors", default="3,6,8,10")
    ap.add_argument("--noise-pct", type=float, default=5.0)
    ap.add_argument("--mass-pct", type=float, default=2.0, help="masses off by up to this, uniformly")
    ap.add_argument("--duration", type=float, default=40.0)
    ap.add_argument("--rate", type=float, default=1000.0, help="sensor rate [Hz]")
    ap.add_argument("--skip", nargs="*", default=[], help="leave out records whose name holds one of these")
    ap.add_argument("--draws", type=int, default=400, help="ideal detector's draws per record")
    args = ap.parse_args()
    try:
        sensors = [int(s) for s in args.sensors.split(",")]
    except ValueError:
        sys.exit(f"twin_bound.py: error: --sensors {args.sensors}: floors 1-10, comma separated")
    if not all(1 <= s <= 10 for s in sensors) or len(set(sensors)) != len(sensors):
        sys.exit(f"twin_bound.py: error: --sensors {args.sensors}: floors 1-10, each once")
    for name, v, lo in (("--noise-pct", args.noise_pct, 0), ("--mass-pct", args.mass_pct, 0),
                        ("--duration", args.duration, 0), ("--rate", args.rate, 0), ("--draws", args.draws, 0)):
        if not (np.isfinite(v) and v > lo):
            sys.exit(f"twin_bound.py: error: {name} {v}: must be a positive number")
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
    print(f"twin bound: bare Table 1 frame, floors {args.sensors} at {args.rate:g} Hz, noise {args.noise_pct:g} % rms, "
          f"masses within +-{args.mass_pct:g} %, first {args.duration:g} s")
    print("record | sd, masses known (largest) | Bayesian bound, masses unknown (median / largest) "
          "| nominal-mass estimator's bias sd (median / largest)")
    covs = []
    for name in sorted(RECORDS):
        if any(s in name for s in args.skip):
            continue
        path = os.path.join(args.records, name)
        try:
            rec = vines.Record.load(path, **RECORDS[name])
        except Exception as e:  # the package's RecordError names the file and the reason
            sys.exit(f"twin_bound.py: error: {e}")
        t = np.arange(0.0, min(args.duration, rec.t[-1]), h)
        ag = np.interp(t, rec.t, rec.acc)
        known, cov, bias = bounds(fisher(k, m, ag, h, sensors, args.noise_pct), mass_sd)
        bayes = np.sqrt(np.diag(cov))
        covs.append(cov)
        print(f"{name[:44]:44s} | {100 * known.max():5.2f} % | {100 * np.median(bayes):5.2f} / {100 * bayes.max():5.2f} % "
              f"| {100 * np.median(bias):5.2f} / {100 * bias.max():5.2f} %", flush=True)
    (z, floor), row = ideal_detector(covs, args.draws)
    print(f"ideal detector (errors at the Bayesian bound; alarm above max({z:g} sd, {floor:g} %)): "
          f"false alarms {row[0]:.1f} %; 5 % loss located {row[1]:.1f} %, size within 1.5 points {row[2]:.1f} %; "
          f"10 % loss located {row[3]:.1f} %, size within 2 points {row[4]:.1f} %")


if __name__ == "__main__":
    main()
