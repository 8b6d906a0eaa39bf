"""The package holds the command line's limits and names the argument in
every refusal: a sweep's threads (1-1024 as --threads, 0 every core) and a
plan above 1,000,000 runs (--large), refused before it takes memory; a Loop
stepped by one thread at a time; arrays the loop cannot honour (masked,
bool, str, object) and numbers that are not numbers refused."""

import os
import signal
import threading

import numpy as np
import pytest

import vines
from conftest import scene_path


def test_sweep_threads_within_the_command_lines_range(vi):
    for threads in (100000, 1025, -1):
        with pytest.raises(ValueError, match="threads: %d; must be 0 .every core. to 1024" % threads):
            vines.sweep(vi, grid={"vines.beta": [1.2]}, threads=threads)
    with pytest.raises(TypeError, match="threads: an int"):
        vines.sweep(vi, grid={"vines.beta": [1.2]}, threads=2.5)


def test_a_plan_of_millions_of_runs_needs_large(vi):
    # 10,000,000 runs: refused at once, naming the size and the way out,
    # before the plan is built (the interpreter's memory stays small).
    grid = {"vines.beta": {"from": 1.0, "to": 2.0, "count": 10000}, "vines.eps": {"from": 0.1, "to": 0.9, "count": 1000}}
    with pytest.raises(ValueError, match="10000000 runs .more than 1000000.*pass large=True"):
        vines.sweep(vi, grid=grid)
    with pytest.raises(TypeError, match="large: a bool"):
        vines.sweep(vi, grid={"vines.beta": [1.2]}, large="yes")


def test_a_loop_is_stepped_by_one_thread_at_a_time(vi):
    # Eight threads on one Loop: one steps, the others are refused (before,
    # they stepped it at once and broke its state: energy residual 0.06-0.93).
    loop = vines.Loop(vi)
    a = vines.samples(vi)
    loop.reset(a[0])
    errors, done = [], []
    start = threading.Barrier(8)

    def worker():
        start.wait()
        try:
            done.append(loop.run(a[1:]))
        except RuntimeError as e:
            errors.append(str(e))

    threads = [threading.Thread(target=worker) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(done) + len(errors) == 8 and len(done) >= 1
    assert all("running samples in another thread" in e for e in errors)
    # Whatever ran, ran whole and alone: each run is the record once more
    # from where the last left off, so the state is that of len(done) runs
    # in turn, and the energy balance holds.
    ref = vines.Loop(vi)
    ref.reset(a[0])
    for _ in done:
        ref.run(a[1:])
    assert loop.state.data == ref.state.data
    # While a run holds the loop, every other call is refused too.
    slow = vines.Loop(vi)
    slow.reset(0.0)
    long = np.tile(a, 50)
    t = threading.Thread(target=slow.run, args=(long,))
    t.start()
    refused = None
    while t.is_alive() and refused is None:
        try:
            slow.step(0.0)
        except RuntimeError as e:
            refused = str(e)
    t.join()
    assert refused is not None and "running samples in another thread" in refused


@pytest.mark.parametrize("samples, kind", [
    (np.ma.masked_array([0.1, 0.2, 0.3], mask=[0, 1, 0]), "a masked array"),
    (np.array([True, False, True]), "not bool"),
    (np.array(["0.1", "0.2"]), "not <U3"),
    (np.array([0.1, None], dtype=object), "not object"),
    (np.array([0.1 + 1j]), "not complex128"),
])
def test_loop_run_refuses_arrays_it_cannot_honour(vi, samples, kind):
    loop = vines.Loop(vi)
    loop.reset(0.0)
    with pytest.raises(TypeError, match="vines.Loop.run: samples: .*%s" % kind):
        loop.run(samples)


def test_numbers_are_checked_and_named(vi):
    loop = vines.Loop(vi)
    with pytest.raises(TypeError, match="vines.Loop.reset: a0: a number .int or float., not str"):
        loop.reset("0")
    loop.reset(0.0)
    with pytest.raises(TypeError, match="vines.Loop.step: a_g: a number .int or float., not str"):
        loop.step("a")
    with pytest.raises(TypeError, match="vines.Loop.step: a_g: a number .int or float., not bool"):
        loop.step(True)
    with pytest.raises(ValueError, match="vines.Loop.step: a_g: .* does not fit a double"):
        loop.step(10 ** 400)
    with pytest.raises(ValueError, match="vines.Record: t0: nan is not finite"):
        vines.Record([0.1, 0.2, 0.3], dt=0.01, t0=float("nan"))
    with pytest.raises(TypeError, match="vines.Record: dt: a number .int or float., not str"):
        vines.Record([0.1, 0.2, 0.3], dt="x")
    with pytest.raises(ValueError, match="vines.Record: dt: inf is not finite"):
        vines.Record([0.1, 0.2, 0.3], dt=float("inf"))
    with pytest.raises(vines.RecordError, match="dt 1.8.*e\\+19 s is outside"):
        vines.Record([0.1, 0.2, 0.3], dt=2 ** 64)
    with pytest.raises(TypeError, match="vines.Record: acc: numbers .*not bool"):
        vines.Record([True, False, True], dt=0.01)


def test_ctrl_c_stops_a_long_loop_run():
    # Ctrl-C 0.6 s into Loop.run of 10,750,000 samples (El Centro at 1 kHz,
    # 200 times; the samples' checks take 0.1-0.2 s, the run 2.4 s here):
    # KeyboardInterrupt at the end of a chunk of 65,536 samples, the loop
    # whole there (before, the whole array ran first).
    scene = vines.Scene.load(scene_path("elcentro_vines"))
    loop = vines.Loop(scene)
    a = np.tile(vines.samples(scene), 200)
    loop.reset(a[0])
    timer = threading.Timer(0.6, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        loop.run(a[1:])
    timer.join()
    k = round(loop.state.t * 1000)
    assert 0 < k < len(a) - 1
    assert k % 65536 == 0
