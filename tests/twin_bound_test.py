#!/usr/bin/env python3
"""tools/twin_bound.py's bounds checked against estimators that reach them.

On a 3-story frame sensed at its roof: the output-error least-squares estimate of the stiffness
factors (Gauss-Newton, masses known), over 40 noise seeds, scatters as the Cramer-Rao bound says;
fitted to a truth whose masses are off, without noise, it moves by the bias the bound predicts.
Also the FFT simulation against a step-by-step recursion. Usage: twin_bound_test.py SOURCE_DIR
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(sys.argv[1], "tools"))
import twin_bound as tb  # noqa: E402

K = np.array([3.0e7, 2.5e7, 2.0e7])
M = np.array([1.0e5, 1.0e5, 0.8e5])
H, SENSORS, NOISE = 0.002, [3], 5.0
rng = np.random.default_rng(7)
AG = np.convolve(rng.standard_normal(5000), np.ones(25) / 5, mode="same")  # 10 s, band-limited, ~1 m/s^2


def recursion(k, m, ag):
    """The same outputs, integrated step by step with the exact (ZOH) transition (the
    check is of the FFT simulation: the state space is tools/twin_bound.py's)."""
    A, b, C = tb.state_space(k, m, SENSORS)
    lam, V = np.linalg.eig(A)
    Ad = (V @ np.diag(np.exp(lam * H)) @ np.linalg.inv(V)).real
    Bd = (V @ np.diag((np.exp(lam * H) - 1) / lam) @ np.linalg.inv(V)).real @ b
    x, out = np.zeros(len(b)), []
    for a in ag:
        out.append(C @ x)
        x = Ad @ x + Bd * a
    return np.array(out)


def fit(y, m):
    """Output-error Gauss-Newton on log k from y, masses m assumed."""
    theta = np.zeros(3)
    for _ in range(6):
        k = K * np.exp(theta)
        r = (y - tb.outputs(k, m, AG, H, SENSORS)).ravel()
        J = np.array([((tb.outputs(k * np.exp(e), m, AG, H, SENSORS)
                        - tb.outputs(k * np.exp(-e), m, AG, H, SENSORS)) / 2e-5).ravel()
                      for e in np.eye(3) * 1e-5]).T
        theta += np.linalg.lstsq(J, r, rcond=None)[0]
    return theta


def main():
    failures = []
    y0 = tb.outputs(K, M, AG, H, SENSORS)
    err = np.abs(y0 - recursion(K, M, AG)).max() / np.abs(y0).max()
    print(f"FFT against recursion: {err:.1e} relative")
    if err > 1e-9:
        failures.append("the FFT simulation differs from the recursion")

    F = tb.fisher(K, M, AG, H, SENSORS, NOISE)
    known, _, _ = tb.bounds(F, 0.01)
    sd = NOISE / 100 * np.sqrt((y0 ** 2).mean(axis=0))
    est = np.array([fit(y0 + sd * np.random.default_rng(s).standard_normal(y0.shape), M) for s in range(40)])
    ratio = est.std(axis=0, ddof=1) / known
    print(f"Cramer-Rao sd {np.round(100 * known, 3)} %, estimates' sd over 40 seeds: ratio {np.round(ratio, 2)}")
    if not np.all((ratio > 0.7) & (ratio < 1.3)):
        failures.append("the estimates' scatter is not the Cramer-Rao bound")
    if np.abs(est.mean(axis=0)).max() > 3 * known.max() / np.sqrt(40) + 1e-4:
        failures.append("the estimates are biased with the masses right")

    delta = np.array([0.01, -0.01, 0.005])
    moved = fit(tb.outputs(K, M * np.exp(delta), AG, H, SENSORS), M)
    predicted = np.linalg.solve(F[:3, :3], F[:3, 3:]) @ delta
    print(f"masses off by {delta}: fit moved {np.round(moved, 5)}, bound predicts {np.round(predicted, 5)}")
    if np.abs(moved - predicted).max() > 0.15 * np.abs(predicted).max() + 5e-4:
        failures.append("the nominal-mass bias is not the predicted one")

    (z, floor), row = tb.ideal_detector([np.eye(10) * 1e-6], 200)
    print(f"ideal detector, sd 0.1 %: {np.round(row, 1)}")
    if row[0] > 0 or min(row[1:]) < 100:
        failures.append("an estimator 10 times better than needed misses")
    for f in failures:
        print("FAILED:", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
