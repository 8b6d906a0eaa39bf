"""Numbers and lists as numpy holds them, taken exactly in every entry
point; arguments of the wrong type refused with a TypeError naming what was
expected; the study's and the record's rules those of the program."""

import os
import subprocess

import numpy as np
import pytest
from conftest import GROUND_MOTIONS, STUDY, VINES_EXE, same_result, scene_path

import vines


def test_numpy_scalars_are_taken_exactly(vi):
    plain = vi.with_({"vines.beta": 1.5, "vines.eps": float(np.float32(0.7))})
    from_numpy = vi.with_({"vines.beta": np.float64(1.5), "vines.eps": np.float32(0.7)})
    assert from_numpy.to_dict()["vines"]["eps"] == float(np.float32(0.7)) != 0.7
    assert from_numpy == plain
    ints = vi.with_({"device.floor": np.int64(10), "loop.energy_ledger": np.bool_(False)})
    assert ints.to_dict()["loop"]["energy_ledger"] is False and ints.to_dict()["device"]["floor"] == 10
    # The same run from either.
    same_result(vines.run(from_numpy), vines.run(plain))


def test_arrays_are_lists_in_dicts_and_grids(vi):
    masses = np.full(3, 1.0e5, dtype=np.float32)
    scene = vines.Scene.from_dict({
        "frame": {"preset": "custom", "masses_kg": masses, "stiffnesses_n_per_m": np.array([2e7, 2e7, 2e7]), "damping": np.str_("modal"),
                  "modal_zeta": np.float16(0.02)},
        "record": {"path": "elcentro_1940_ns_2688pts_dt002_time_g.dat", "format": "time-accel"},
    })
    frame = scene.to_dict()["frame"]
    assert frame["masses_kg"] == [1.0e5] * 3 and scene.stories == 3
    assert frame["modal_zeta"] == float(np.float16(0.02))
    betas = np.linspace(1.2, 1.5, 3)
    a = vines.sweep(vi, grid={"vines.beta": betas}, threads=1)
    b = vines.sweep(vi, grid={"vines.beta": betas.tolist()}, threads=1)
    assert a.tobytes() == b.tobytes() and list(a["vines.beta"]) == betas.tolist()
    c = vines.sweep(vi, cases=[{"vines.beta": np.float64(1.2)}], set={"vines.eps": np.float32(0.5)})
    assert c["status"][0] == "ok"


def test_a_value_with_no_exact_double_is_refused(vi):
    with pytest.raises(TypeError, match="vines.beta.*no exact double"):
        vi.with_({"vines.beta": np.longdouble(4) / 3})
    with pytest.raises(TypeError, match="vines.beta.*no exact double"):
        vi.with_({"vines.beta": np.longdouble(10) ** 400})  # would be inf as a double
    with pytest.raises(TypeError, match=r"vines\.law: a value of type object \(bool, int, float, str"):
        vi.with_({"vines.law": object()})
    with pytest.raises(TypeError, match="device.kind"):
        vines.Scene.from_dict({"frame": {"preset": "table1"}, "device": {"kind": 1j}})


def test_paths_and_arrays_are_taken_where_natural(vi, tmp_path):
    path = scene_path("elcentro_tmd")
    same_result(vines.run(path), vines.run(vines.Scene.load(path)))
    assert vines.modal(path)["frequency_hz"].shape == (10,)
    rec = vines.Record.load("elcentro_1940_ns_2688pts_dt002_time_g.dat")
    g = rec.acc / 9.80665
    same_result(vines.run(vi, (g, rec.dt)), vines.run(vi, vines.Record(g, rec.dt)))
    same_result(vines.run(vi, rec.path), vines.run(vi, rec))


@pytest.mark.parametrize("call, what", [
    (lambda s: vines.run(42), "vines.run: scene: a vines.Scene or a scene file's path, not int"),
    (lambda s: vines.run(s, 3.0), "vines.run: record: a vines.Record, a record file's path or"),
    (lambda s: vines.modal(None), "vines.modal: scene: a vines.Scene"),
    (lambda s: vines.Loop([s]), "vines.Loop: a vines.Scene"),
    (lambda s: vines.samples(s, [1, 2]), "vines.samples: record"),
    (lambda s: vines.sweep({"vines.beta": [1.2]}), "vines.sweep: scene"),
    (lambda s: vines.Scene.load(3), "vines.Scene.load: a path"),
    (lambda s: vines.Scene.from_dict([1]), "vines.Scene.from_dict.*a dict, not list"),
    (lambda s: vines.Record.load(None), "vines.Record.load: a path"),
    (lambda s: vines.Record(["a", "b"], 0.01), "acc: numbers"),
    (lambda s: vines.sweep(s, cases={"vines.beta": 1.2}), "cases: a list, not dict"),
    (lambda s: vines.sweep(s, threads=1.5), "threads: an int"),
    (lambda s: vines.Loop(s).set_state("state"), "a vines.LoopState, not str"),
])
def test_wrong_types_name_what_was_expected(vi, call, what):
    with pytest.raises(TypeError, match=what):
        call(vi)


def test_a_scene_path_that_is_missing_names_it():
    with pytest.raises(vines.SceneError, match="x.toml"):
        vines.run("x.toml")
    with pytest.raises(vines.SceneError, match="x.toml"):
        vines.modal("x.toml")


def test_sweep_refuses_bad_keys_and_threads_before_running(vi):
    for spec, what in (({"grid": {"vines.betta": [1.2, 1.3]}}, "vines.betta: not a scene key"),
                       ({"set": {"vines.beta": 1.2}, "grid": {"vines.beta": [1.3]}}, "set in both"),
                       ({"cases": [{"vinesbeta": 1.2}]}, "vinesbeta: keys are table.key"),
                       ({"grid": {"vines.beta": {"from": 1.2, "to": 1.4, "stepp": 0.1}}}, "unknown range key"),
                       ({"grid": {"vines.beta": [1.2]}, "group_by": "vines.eps"}, "group_by")):
        with pytest.raises(vines.SceneError, match=what):
            vines.sweep(vi, **spec)


def cli(*args):
    return subprocess.run([VINES_EXE, *args], capture_output=True, text=True)


def test_the_shortest_record_is_the_programs(vi, tmp_path):
    scene = scene_path("elcentro_vines")
    # One point: no interval, refused by both with the same rule.
    one = tmp_path / "one.dat"
    one.write_text("0.1\n")
    res = cli("run", scene, "--record", str(one), "--record-format", "accel", "--record-dt", "0.01",
              "--out", str(tmp_path / "o1"), "--quiet")
    assert res.returncode != 0 and "at least 2 points" in res.stderr
    with pytest.raises(vines.RecordError, match="at least 2 points, it has 1"):
        vines.Record([0.1], 0.01)
    with pytest.raises(vines.RecordError, match="at least 2 points, it has 1"):
        vines.Record.load(one, format="accel", dt=0.01)
    # Shorter than one step at the sensor rate: refused by both.
    short = tmp_path / "short.dat"
    short.write_text("0 0.0\n0.0001 0.1\n")
    res = cli("run", scene, "--record", str(short), "--out", str(tmp_path / "o2"), "--quiet")
    assert res.returncode != 0 and "record too short for one step at the sensor rate" in res.stderr
    with pytest.raises(vines.RecordError, match="record too short for one step at the sensor rate"):
        vines.run(vi.with_({"loop.sensor_rate_hz": 1000.0}), vines.Record([0.0, 0.1], 0.0001))
    with pytest.raises(vines.RecordError, match="too short"):
        vines.samples(vi.with_({"loop.sensor_rate_hz": 1000.0}), ([0.0, 0.1], 0.0001))
    # Two points, one interval of several steps: run by both, the same.
    two = tmp_path / "two.dat"
    two.write_text("0 0.0\n0.01 0.1\n")
    res = cli("run", scene, "--record", str(two), "--out", str(tmp_path / "o3"), "--quiet")
    assert res.returncode == 0, res.stderr
    assert vines.run(scene, two).status == "ok"


def test_an_infinite_value_is_named_as_such(vi):
    with pytest.raises(vines.SceneError, match="vines.beta: must be a finite number > 1"):
        vi.with_({"vines.beta": float("inf")})
    with pytest.raises(vines.SceneError, match="vines.young_pa: must be finite and > 0"):
        vi.with_({"vines.young_pa": np.inf})


def test_record_load_looks_in_the_ground_motions_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    name = "kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2"
    kobe = vines.Record.load(name)
    assert os.path.samefile(kobe.path, os.path.join(GROUND_MOTIONS, name))
    with pytest.raises(vines.RecordError, match=r'"no_such.at2" not found; tried .*ground'):
        vines.Record.load("no_such.at2")
