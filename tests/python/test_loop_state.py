"""A loop's state: saved and restored bit for bit, and set physically (an
estimator's update) with the run then going on as the physics says."""

import math

import numpy as np
import pytest
from conftest import same_totals

import vines


def test_a_saved_state_restores_the_run_bit_for_bit(vi):
    a = vines.samples(vi)
    loop = vines.Loop(vi)
    loop.reset(a[0])
    loop.run(a[1:1200])
    saved = loop.state
    assert saved.t == pytest.approx(1199 / vi.sensor_rate_hz) and saved.x.shape == (10,)
    assert -1 < saved.particle_x < 1 and math.isnan(saved.tmd_x)
    end = loop.run(a[1200:])
    totals = loop.totals
    # Rewound to the saved state, the same loop runs the rest again, the same.
    back = loop.set_state(saved)
    assert back.t == saved.t and back.x.tobytes() == saved.x.tobytes()
    assert loop.run(a[1200:]).x.tobytes() == end.x.tobytes()
    same_totals(loop.totals, totals)
    # So does another loop of the scene.
    other = vines.Loop(vi)
    other.set_state(saved)
    assert other.run(a[1200:]).x.tobytes() == end.x.tobytes()
    same_totals(other.totals, totals)


def test_a_state_of_another_scene_is_refused(vi, tmd):
    loop = vines.Loop(tmd)
    loop.reset(0.0)
    theirs = vines.Loop(vi)
    theirs.reset(0.0)
    with pytest.raises(ValueError, match="vines.Loop.set_state"):
        loop.set_state(theirs.state)
    stiffer = vines.Loop(vi.with_({"frame.stiffness_scale": 0.9}))
    stiffer.reset(0.0)
    with pytest.raises(ValueError, match="another model"):
        stiffer.set_state(theirs.state)


def test_a_physical_state_set_is_free_vibration_from_it(bare):
    """The bare frame set to its first mode shape, at rest, with no ground
    motion: the top floor's free vibration is the first mode's, with its
    frequency and damping ratio (modal report)."""
    m = vines.modal(bare)
    f, zeta, phi = m["frequency_hz"][0], m["damping_ratio"][0], m["mode_shapes"][0]
    phi = 0.01 * phi / phi[-1]  # top floor at 1 cm
    loop = vines.Loop(bare.with_({"loop.sensor_rate_hz": 1000.0}))
    loop.reset(0.0)
    out = loop.set_state(x=phi, v=np.zeros(10))
    np.testing.assert_allclose(out.x, phi, rtol=1e-12, atol=1e-16)
    t = np.arange(1, 4001) / 1000.0
    top = np.array([loop.step(0.0).x[-1] for _ in t])
    wn = 2 * math.pi * f
    wd = wn * math.sqrt(1 - zeta ** 2)
    expected = 0.01 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta ** 2) * np.sin(wd * t))
    np.testing.assert_allclose(top, expected, atol=1e-9)


def test_an_estimators_update_keeps_time_peaks_and_the_energy_balance(vi):
    a = vines.samples(vi)
    truth, model = vines.Loop(vi), vines.Loop(vi.with_({"frame.stiffness_scale": 0.95}))
    truth.reset(a[0])
    model.reset(a[0])
    truth.run(a[1:500])
    model.run(a[1:500])
    peak = model.totals["peak_top_displacement_m"]
    now = truth.state
    out = model.set_state(x=now.x, v=now.v, particle_x=now.particle_x, particle_v=now.particle_v)
    np.testing.assert_allclose(out.x, now.x, rtol=1e-12, atol=1e-15)
    assert out.particle_x == pytest.approx(now.particle_x, abs=1e-15) and out.t == now.t
    assert model.totals["peak_top_displacement_m"] == peak and model.totals["steps"] == 499
    model.run(a[500:])
    # The energy the update stored counts as put in: the ledger still balances
    # as closely as an uninterrupted run's.
    plain = vines.run(vi.with_({"frame.stiffness_scale": 0.95}))
    assert model.totals["steps"] == plain.counters["steps"]
    assert model.totals["energy_balance_residual"] < max(1e-9, 10 * plain.energy_balance_residual)


def test_a_physical_state_is_checked(vi, tmd):
    loop = vines.Loop(vi)
    with pytest.raises(RuntimeError, match="reset"):
        loop.set_state(x=np.zeros(10))
    loop.reset(0.0)
    with pytest.raises(ValueError, match=r"x: one value a floor \(10\)"):
        loop.set_state(x=np.zeros(3))
    with pytest.raises(ValueError, match="particle_x"):
        loop.set_state(particle_x=1.0)  # a metre: past the walls
    with pytest.raises(ValueError, match="tmd_x"):
        loop.set_state(tmd_x=0.01)  # a VI NES has no TMD
    t = vines.Loop(tmd)
    t.reset(0.0)
    assert t.set_state(tmd_x=0.02, tmd_v=-0.1).tmd_x == pytest.approx(0.02, abs=1e-15)
    with pytest.raises(ValueError, match="particle_x"):
        t.set_state(particle_x=0.0)
