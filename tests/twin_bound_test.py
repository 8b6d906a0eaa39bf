#!/usr/bin/env python3
"""tools/twin_bound.py's bounds checked against estimators that reach them.

On a 3-story frame sensed at its roof: the output-error least-squares estimate of the stiffness
factors (Gauss-Newton, masses known), over 40 noise seeds, scatters as the Cramer-Rao bound says;
fitted to a truth whose masses are off, without noise, it moves by the bias the bound predicts.
Also the FFT simulation against a step-by-step recursion. The one-story GLRT (tools/twin_glrt.py)
against the estimator it models: masses drawn within 2 %, the output-error fit of the stiffnesses
and masses (the masses' prior the tool's) over seeds, the GLRT on its estimates: their whitened
errors, the located share of a loss and the sizes' scatter are the tool's predictions within
sampling error; the same for the fit that keeps the nominal masses (whitened by the bias
covariance too, and not). The VI NES bound's information with every impact unknown
(tools/twin_bound_vines.py, a Kalman whitening) against the Schur complement of an explicit
regression with three free kick directions at each kicked period. Usage: twin_bound_test.py
SOURCE_DIR
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(sys.argv[1], "tools"))
import twin_bound as tb  # noqa: E402
import twin_bound_vines as tv  # noqa: E402
import twin_glrt as tg  # noqa: E402

K = np.array([3.0e7, 2.5e7, 2.0e7])
M = np.array([1.0e5, 1.0e5, 0.8e5])
H, SENSORS, NOISE = 0.002, [3], 5.0
LOSS = 2.5  # the GLRT checks' loss [%]: located in about half the seeds (57 % predicted)
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


def fit(y, m, sd=None, mass_half=None, iterations=6):
    """Output-error Gauss-Newton on log k from y, masses m assumed; with mass_half, on
    (log k, log m) with the masses' Gaussian prior of the uniform's sd (the tool's), each
    channel weighted by its noise sd. Returns the log factors (k, then m if fitted)."""
    n = 6 if mass_half else 3
    w = 1.0 if sd is None else 1.0 / sd
    prior = np.zeros(n) if not mass_half else np.r_[np.zeros(3), np.full(3, 3 / mass_half ** 2)]
    theta = np.zeros(n)
    for _ in range(iterations):
        par = lambda t: (K * np.exp(t[:3]), m * np.exp(np.r_[t, np.zeros(3)][3:6]))
        r = ((y - tb.outputs(*par(theta), AG, H, SENSORS)) * w).ravel()
        J = np.array([((tb.outputs(*par(theta + e), AG, H, SENSORS)
                        - tb.outputs(*par(theta - e), AG, H, SENSORS)) * w / 2e-5).ravel()
                      for e in np.eye(n) * 1e-5]).T
        theta += np.linalg.solve(J.T @ J + np.diag(prior), J.T @ r - prior * theta)
    return theta


def glrt_checks(F, y0, failures):
    """The one-story GLRT's predictions against the fits over seeds (module docstring)."""
    sd = NOISE / 100 * np.sqrt((y0 ** 2).mean(axis=0))
    half, loss, seeds = 0.02, LOSS, 36
    unknown = tg.ErrorModel(*tg.with_masses_unknown(F, half), half)
    nominal = tg.ErrorModel(*tg.with_nominal_masses(F), half)
    W = np.linalg.inv(unknown.cov())
    predicted = tg.campaign(unknown, losses=(loss,), draws=4000)
    thr = predicted["threshold"]
    rng = np.random.default_rng(11)
    whitened, whitened_nominal, ignored, located, size_err = [], [], [], [], []
    for s in range(2 * seeds):
        mu = rng.uniform(-half, half, 3)
        story = s % 3
        k = K.copy()
        if s >= seeds:  # the damaged half: one story lost
            k[story] *= 1 - loss / 100
        y = tb.outputs(k, M * np.exp(mu), AG, H, SENSORS) + sd * rng.standard_normal(y0.shape)
        th = -fit(y, M, sd, half, iterations=4)[:3]  # loss coordinates: -log of the factor
        if s < seeds:
            whitened.append(th @ W @ th)
            thn = -fit(y, M, sd, iterations=3)
            whitened_nominal.append(thn @ np.linalg.solve(nominal.cov(), thn))
            ignored.append(thn @ np.linalg.solve(nominal.Cn, thn))
        else:
            stat, j, delta = tg.glrt(W, th[:, None])
            located.append(stat[0] > thr and j[0] == story)
            size_err.append((1 - np.exp(-delta[story, 0])) * 100 - loss)
    chi = np.mean(whitened) / 3
    chi_n, chi_i = np.mean(whitened_nominal) / 3, np.mean(ignored) / 3
    rate, want = 100 * np.mean(located), predicted[loss][0]
    scatter = np.sqrt(np.mean(np.square(size_err))) / np.sqrt(np.mean(predicted["size_sd"] ** 2))
    print(f"GLRT, masses unknown within 2 %: whitened errors' mean square per story {chi:.2f} (1 predicted) over "
          f"{seeds} seeds; {loss:g} % loss located in {rate:.0f} % of {seeds} seeds, predicted {want:.0f} %; "
          f"size error rms / predicted sd {scatter:.2f}")
    print(f"nominal masses: mean square per story {chi_n:.2f} whitened by noise and bias, {chi_i:.1f} by the noise "
          "alone")
    band = 0.75 * np.sqrt(2 / (3 * seeds)) * 3  # 3 sd of a mean of 3 seeds x chi-square(1), loosely correlated
    if abs(chi - 1) > band:
        failures.append("the masses-unknown estimates do not err by the tool's covariance")
    if abs(chi_n - 1) > band:
        failures.append("the nominal-mass estimates do not err by the noise plus the bias covariance")
    if chi_i < 3:
        failures.append("the nominal-mass bias does not dominate the noise (the test's frame no longer shows it)")
    if not 15 < want < 85:
        failures.append(f"the predicted located share {want:.0f} % is too near 0 or 100 to test")
    if abs(rate - want) > 3 * np.sqrt(want * (100 - want) / seeds) + 2:
        failures.append("the GLRT's located share is not the predicted one")
    if not 0.7 < scatter < 1.35:
        failures.append("the GLRT's sizes do not scatter by the predicted sd")


def vines_checks(failures):
    """The impulse input against the recursion with the impulse applied at mid-step, and
    information() against the regression it stands for (floors 2 and 3 sensed: the roof's
    channel is the one left out where touched)."""
    sensors, n = [2, 3], 3
    A, b, C = tb.state_space(K, M, sensors)
    imp = np.zeros(len(AG))
    kicked = np.zeros(len(AG), bool)
    kicked[[400, 1300, 2500, 4100]] = True  # apart: the regression below is solved accurately
    imp[kicked] = np.array([3e4, -2e4, 5e4, -4e4])  # N s over the period
    touched = np.roll(kicked, 1)  # the samples taken at a contact's end
    lam, V = np.linalg.eig(A)
    Ad = (V @ np.diag(np.exp(lam * H)) @ np.linalg.inv(V)).real
    Bd = (V @ np.diag((np.exp(lam * H) - 1) / lam) @ np.linalg.inv(V)).real @ b
    Bi = (V @ np.diag(np.exp(lam * H / 2)) @ np.linalg.inv(V)).real[:, 2 * n - 1] / M[-1]
    x, out = np.zeros(2 * n), []
    for a, p in zip(AG, imp):
        out.append(C @ x)
        x = Ad @ x + Bd * a + Bi * p
    y = tb.outputs(K, M, AG, H, sensors, imp)
    err = np.abs(y - np.array(out)).max() / np.abs(y).max()
    print(f"impulses: FFT against recursion {err:.1e} relative")
    if err > 1e-9:
        failures.append("the impulse input's FFT simulation differs from the recursion")

    sd = NOISE / 100 * np.sqrt((y ** 2).mean(axis=0))
    jac = tb.jacobian(K, M, AG, H, sensors, NOISE, imp=imp, sd=sd)
    F, (before,) = tv.information(jac, A, C, sd, kicked, touched, 1, H, cuts=[2000])
    early, _ = tv.information(jac[:, :2000], A, C, sd, kicked[:2000], touched[:2000], 1, H)
    rows = np.ones((len(AG), 2), bool)
    rows[touched, 1] = False
    Phi, G = tv._discrete(A, H, np.eye(2 * n)[:, [2 * n - 1]])
    cols = []
    for t0 in np.flatnonzero(kicked):
        for d in range(3):
            resp, x = np.zeros((len(AG), 2)), G[:, d].copy()
            for t in range(t0 + 1, len(AG)):
                resp[t] = C @ x / sd
                x = Phi @ x
            cols.append(resp[rows])
    # The Schur complement by QR: the three profiles respond nearly in parallel (the kicks'
    # columns have a condition number of about 2e11), which normal equations would not solve.
    Jt = np.array([j[rows] for j in jac]).T
    Q, _ = np.linalg.qr(np.array(cols).T)
    ref = Jt.T @ Jt - (Q.T @ Jt).T @ (Q.T @ Jt)
    rel = np.abs(F - ref).max() / np.abs(ref).max()
    lost = 1 - np.trace(ref) / np.trace(np.einsum("itc,jtc->ij", jac, jac))
    cut = np.abs(before - early).max() / np.abs(early).max()
    print(f"kicks unknown: information against the regression's Schur complement {rel:.1e} relative "
          f"({100 * lost:.1f} % of the trace lost to the kicks); before a cut against its own run {cut:.1e}")
    if rel > 1e-6 or lost <= 0:
        failures.append("the VI NES bound's information is not the regression's")
    if cut > 1e-9:
        failures.append("the information before a cut is not that of the samples before it")


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
    glrt_checks(F, y0, failures)
    vines_checks(failures)
    for f in failures:
        print("FAILED:", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
