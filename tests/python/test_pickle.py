"""Scenes, records, loops and results pickle and deep-copy: a run of the
copy is the run of the original, bit for bit, in this process or in a pool
of others."""

import copy
import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest
from conftest import same_result, same_totals

import vines


def round_trips(obj):
    return [pickle.loads(pickle.dumps(obj, protocol=p)) for p in (2, pickle.HIGHEST_PROTOCOL)] + [copy.deepcopy(obj)]


def test_a_scene_pickles_with_its_overrides(vi):
    beta = vi.with_({"vines.beta": 1.5})
    for again in round_trips(beta):
        assert again == beta and again is not beta and hash(again) == hash(beta)
        assert again.overrides == beta.overrides and repr(again) == repr(beta)
    same_result(vines.run(round_trips(beta)[0]), vines.run(beta))
    assert beta != vi


def test_records_pickle_from_a_file_and_from_samples(vi):
    rec = vines.Record.load("elcentro_1940_ns_2688pts_dt002_time_g.dat")
    arr = vines.Record(np.sin(np.arange(500) / 20.0) * 0.2, 0.01, t0=0.5, name="sine")
    for r in (rec, arr):
        for again in round_trips(r):
            assert (again.path, again.dt, again.t0, len(again)) == (r.path, r.dt, r.t0, len(r))
            assert again.acc.tobytes() == r.acc.tobytes()
        same_result(vines.run(vi, round_trips(r)[0]), vines.run(vi, r))


def test_a_result_pickles_as_plain_data(tmd):
    r = vines.run(tmd)
    for again in round_trips(r):
        same_result(again, r)
        assert again.x_r == r.x_r and again.bare.x.tobytes() == r.bare.x.tobytes()


def test_a_loop_pickles_in_the_middle_of_a_run(vi):
    a = vines.samples(vi)
    loop = vines.Loop(vi)
    loop.reset(a[0])
    loop.run(a[1:900])
    assert loop.totals["contacts"] > 0  # a run with contacts behind it
    copies = round_trips(loop)
    last = loop.run(a[900:])
    for again in copies:
        assert again.state.t == pytest.approx(899 / vi.sensor_rate_hz)
        out = again.run(a[900:])
        assert out.x.tobytes() == last.x.tobytes() and out.particle_x == last.particle_x
        same_totals(again.totals, loop.totals)
    fresh = round_trips(vines.Loop(vi))[0]  # not reset yet: still needs a reset
    with pytest.raises(RuntimeError, match="reset"):
        fresh.step(0.0)


def beta_run(scene):
    return vines.run(scene)


def test_runs_map_over_a_process_pool(vi):
    scenes = [vi.with_({"vines.beta": b}) for b in (1.2, 1.35, 1.5, 1.8)]
    with ProcessPoolExecutor(max_workers=2) as pool:
        pooled = list(pool.map(beta_run, scenes))
    for p, s in zip(pooled, scenes):
        same_result(p, vines.run(s))
    # vines.run itself maps too (it is a module-level function).
    with ProcessPoolExecutor(max_workers=2) as pool:
        direct = list(pool.map(vines.run, scenes[:2]))
    assert [r.x_r for r in direct] == [r.x_r for r in pooled[:2]]
