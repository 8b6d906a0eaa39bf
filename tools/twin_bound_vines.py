"""The information bound of the VI NES building (tools/twin_bound.py --device vines; docs/twin.md
section 7): what its impacts leave in the data for any estimator.

Between impacts the VI NES building is the bare frame: the sphere flies freely, the box is part of
the top floor. An impact is a force on the top floor that no sensor measures. The bound treats it
as wholly unknown:
- over each sensor period in which the sphere touches a wall, the frame's state takes an unknown
  kick: the response to the force's profile over the period to its second moment (three
  directions, exact to O((omega h)^3) for every profile);
- the top floor's accelerometer reads an unknown share of the force at each sample during a
  contact, so those samples carry nothing (they are left out);
- the noise is 5 % of each channel's RMS as the campaign draws it, impacts' spikes included.
The impacts are the truth's own (`vines.run` of the campaign's VI NES building with the sphere at
--sphere-x0, at 4 sensor samples a period to see each contact). The information of the stiffness
and mass factors left once every kick is eliminated is the Gauss-Markov estimate's with the kicks
as free parameters: the sensitivities whitened by a Kalman filter whose kick variance is
unbounded at the kick periods (the three directions made orthonormal in their outputs, each of
prior sd 1e4: the limit within about 1e-8, tests/twin_bound_test.py), and zero elsewhere (the
frame's state is otherwise known from rest).
"""
import numpy as np

OVERSAMPLE = 4  # the truth's run samples each sensor period this many times
KICK_SD = 1e4   # each kick direction's prior sd, its outputs orthonormal (unbounded)


def impacts(vines, tables, h, duration):
    """The truth's impacts on the top floor: (impulse over each sensor period [N s], kick
    periods (bool), samples taken during a contact (bool), the floors' absolute accelerations at
    the sensor samples (samples x floors)); tables: the campaign's scene tables
    (twin_campaign_cases.building), run for duration seconds at OVERSAMPLE / h."""
    rate = OVERSAMPLE / h
    t = dict(tables, loop=dict(tables.get("loop", {}), sensor_rate_hz=rate), output={"rate_hz": rate})
    t["record"] = dict(t["record"], duration_s=duration)
    r = vines.run(vines.Scene.from_dict(t, origin="twin_bound_vines"))
    force = -np.nan_to_num(np.asarray(r.contact_force))  # on the box, so on the top floor
    steps = (len(force) - 1) // OVERSAMPLE
    f = force[: steps * OVERSAMPLE + 1]
    segs = np.lib.stride_tricks.sliding_window_view(f, OVERSAMPLE + 1)[::OVERSAMPLE]
    impulse = (segs[:, :-1] + segs[:, 1:]).sum(axis=1) * h / (2 * OVERSAMPLE)  # trapezoids
    kicked = np.any(segs != 0, axis=1)
    touched = f[::OVERSAMPLE] != 0
    acc = np.asarray(r.acc)[: steps * OVERSAMPLE + 1 : OVERSAMPLE]
    return impulse, kicked, touched, acc


def _discrete(A, h, B):
    """(exp(A h), the state a period's input through B leaves at its end, for the input's
    profiles of degree 0, 1 and 2 over the period: 3 columns an input): the augmented matrix
    exponential (the input and its two derivatives as integrators' states)."""
    from scipy.linalg import expm  # noqa: PLC0415 (host tool)
    n, m = len(A), B.shape[1]
    q = 3 * m
    big = np.zeros((n + q, n + q))
    big[:n, :n] = A
    big[:n, n:n + m] = B
    for p in range(2):  # w0' = w1, w1' = w2, w2' = 0: w0 any quadratic over the period
        big[n + p * m:n + (p + 1) * m, n + (p + 1) * m:n + (p + 2) * m] = np.eye(m)
    E = expm(big * h)
    return E[:n, :n], E[:n, n:]


def information(jac, A, C, sd, kicked, touched, top, h, cuts=()):
    """The Fisher information of the parameters whose whitened output sensitivities are jac
    (params x samples x channels) with a free kick at each kicked period and channel `top` left
    out where touched; A, C the frame's continuous state space (C unwhitened, sd the channels'
    noise). Returns (the whole run's information, the information of the samples before each of
    cuts (sample indices), in the chain rule's sense: the rest is the later samples' given
    these)."""
    nx, (npar, T, ny) = len(A), jac.shape
    top_floor = np.zeros((nx, 1))
    top_floor[-1, 0] = 1.0
    Phi, G = _discrete(A, h, top_floor)
    Cw = C / sd[:, None]
    # The kick directions made orthonormal in their outputs over the next samples (the three
    # profiles' responses are nearly parallel: scaled one by one, a finite prior on their small
    # differences is not yet unbounded).
    O, X = [], G
    for _ in range(4 * nx):
        O.append(Cw @ X)
        X = Phi @ X
    _, sv, vt = np.linalg.svd(np.vstack(O), full_matrices=False)
    seen = sv > 1e-12 * sv[0]
    G = G @ vt.T[:, seen] / sv[seen]
    Q = KICK_SD ** 2 * G @ G.T
    keep_all, keep_top = np.arange(ny), np.array([i for i in range(ny) if i != top])
    xs = np.zeros((nx, npar))   # the filter's estimate of each sensitivity's state
    P = np.zeros((nx, nx))
    F = np.zeros((npar, npar))
    parts, cuts = [], sorted(cuts)
    for t in range(T):
        while len(parts) < len(cuts) and cuts[len(parts)] == t:
            parts.append(F.copy())
        rows = keep_top if touched[t] and top is not None else keep_all
        Cr = Cw[rows]
        e = jac[:, t, rows].T - Cr @ xs
        if P.any():
            S = Cr @ P @ Cr.T + np.eye(len(rows))
            Sinv = np.linalg.inv(S)
            K = P @ Cr.T @ Sinv
            F += e.T @ Sinv @ e
            xs += K @ e
            IKC = np.eye(nx) - K @ Cr
            P = IKC @ P @ IKC.T + K @ K.T
            P = (P + P.T) / 2
        else:
            F += e.T @ e
        xs = Phi @ xs
        P = Phi @ P @ Phi.T
        if kicked[t]:
            P += Q
        elif P.any() and np.trace(Cw @ P @ Cw.T) < 1e-14:
            P[:] = 0.0
    while len(parts) < len(cuts):
        parts.append(F.copy())
    return (F + F.T) / 2, [(p + p.T) / 2 for p in parts]
