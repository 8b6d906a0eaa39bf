"""The Python package against the `vines` program built beside it: the same
scene gives the same summary, bit for bit; the series have the documented
shapes and match timeseries.csv; bad input raises naming the key or file.

Run by CTest (tests/CMakeLists.txt) with PYTHONPATH=<build>/python,
VINES_EXE=<build>/vines and VINES_SOURCE_DIR=<checkout>."""

import csv
import json
import math
import os
import subprocess

import numpy as np
import pytest

import vines

SOURCE = os.environ["VINES_SOURCE_DIR"]
VINES_EXE = os.environ["VINES_EXE"]
SCENES = os.path.join(SOURCE, "data", "scenes")
ELCENTRO = os.path.join(SOURCE, "..", "shared", "data", "ground_motions",
                        "elcentro_1940_ns_2688pts_dt002_time_g.dat")
# What may differ between two runs of the same scene: the loop's wall time.
UNTIMED = {"wall_time_s"}


def cli_run(scene_path, out, *extra):
    subprocess.run([VINES_EXE, "run", scene_path, "--out", str(out), "--quiet", *extra], check=True)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "timeseries.csv")) as f:
        rows = list(csv.DictReader(f))
    return summary, rows


def same_summary(a, b):
    keys = (set(a) | set(b)) - UNTIMED
    diff = [k for k in sorted(keys) if a.get(k) != b.get(k)]
    assert not diff, "summaries differ in %s" % diff


@pytest.fixture(scope="module")
def vines_scene():
    return vines.Scene.load(os.path.join(SCENES, "elcentro_vines.toml"))


@pytest.fixture(scope="module")
def vines_run(tmp_path_factory, vines_scene):
    out = tmp_path_factory.mktemp("cli_vines")
    return vines.run(vines_scene), cli_run(os.path.join(SCENES, "elcentro_vines.toml"), out)


@pytest.mark.parametrize("name", ["elcentro_vines", "elcentro_tmd", "elcentro_bare"])
def test_run_equals_the_program_bit_for_bit(tmp_path, name):
    path = os.path.join(SCENES, name + ".toml")
    result = vines.run(vines.Scene.load(path))
    summary, _ = cli_run(path, tmp_path)
    same_summary(result.summary, summary)


def test_summary_fields_are_attributes(vines_run):
    result, (summary, _) = vines_run
    assert result.x_r == summary["x_r"] and result.E_r == summary["E_r"]
    assert result.peak_top_displacement_m == summary["peak_top_displacement_m"]
    assert result.contacts == 18 and result.status == "ok" and not result.degraded
    with pytest.raises(AttributeError):
        result.no_such_field


def test_series_shapes_units_and_the_csv(vines_run, vines_scene):
    result, (_, rows) = vines_run
    n = vines_scene.stories
    steps = len(result.t)
    assert steps == len(rows)
    # The output rate: 100 rows a second of the 53.76 s record, t = 0 first.
    assert steps == round(53.76 * vines_scene.output_rate_hz) + 1
    assert result.t[0] == 0 and result.t[1] == pytest.approx(1 / vines_scene.output_rate_hz)
    for name in ("x", "v", "acc", "drift"):
        assert getattr(result, name).shape == (steps, n)
        assert result.bare.__dict__[name].shape == (steps, n)
    for name in ("t", "ag", "elastic_energy", "particle_x", "particle_v", "contact_force", "mode"):
        assert getattr(result, name).shape == (steps,)
    # The CSV holds the same numbers to 9 digits.
    for col, arr in (("x10_m", result.x[:, 9]), ("acc3_mps2", result.acc[:, 2]), ("Ee_Js", result.elastic_energy),
                     ("particle_x_m", result.particle_x), ("bare_x_top_m", result.bare.x[:, 9])):
        csv_values = np.array([float(r[col]) for r in rows])
        np.testing.assert_allclose(arr, csv_values, rtol=1e-8, atol=1e-12 * np.abs(arr).max())
    # The continuous-time peak bounds the sampled one, which comes within 1 %.
    sampled = np.abs(result.x[:, -1]).max()
    assert sampled <= result.peak_top_displacement_m <= 1.01 * sampled
    # The particle stays between the walls (to the deepest overlap).
    overlap = result.max_overlap_m
    assert np.all(result.particle_x >= result.wall_left - overlap - 1e-12)
    assert np.all(result.particle_x <= result.wall_right + overlap + 1e-12)


def test_a_record_from_an_array_runs_as_the_file(vines_scene):
    rec = vines.Record.load(ELCENTRO)
    assert len(rec) == 2688 and rec.dt == pytest.approx(0.02)
    assert rec.pga == pytest.approx(0.3487 * 9.80665, rel=1e-3)
    from_array = vines.Record(rec.acc, rec.dt, units="m/s2", t0=rec.t0)
    in_g = vines.Record(rec.acc / 9.80665, rec.dt, t0=rec.t0)  # units="g" (the default)
    np.testing.assert_allclose(in_g.acc, rec.acc, rtol=1e-15)
    a, b = vines.run(vines_scene, from_array), vines.run(vines_scene)
    for key in ("x_r", "E_r", "peak_top_displacement_m", "contacts", "counters"):
        assert a.summary[key] == b.summary[key], key
    assert a.summary["record"]["path"] == "<array>"


def test_record_load_matches_the_record_option(tmp_path, vines_scene):
    kobe = os.path.join(os.path.dirname(ELCENTRO), "kobe_1995_KJMA_000_ns_nga_west2_rsn1106.at2")
    summary, _ = cli_run(os.path.join(SCENES, "elcentro_tmd.toml"), tmp_path, "--record", kobe)
    result = vines.run(vines.Scene.load(os.path.join(SCENES, "elcentro_tmd.toml")), vines.Record.load(kobe))
    same_summary(result.summary, summary)


def test_overrides_and_toml_round_trip(vines_scene):
    wider = vines_scene.with_({"vines.beta": 1.5, "loop.sensor_rate_hz": 200.0}, output__rate_hz=50.0)
    assert wider.sensor_rate_hz == 200.0 and wider.output_rate_hz == 50.0
    assert vines_scene.sensor_rate_hz == 1000.0  # the original is unchanged
    again = vines.Scene.from_toml(wider.to_toml(), origin=vines_scene.origin)
    a, b = vines.run(wider), vines.run(again)
    same_summary(a.summary, b.summary)
    assert a.summary["device_params"]["beta"] == pytest.approx(1.5)


def test_a_scene_from_a_dict():
    scene = vines.Scene.from_dict({
        "scene": {"name": "bare_from_python"},
        "frame": {"preset": "table1"},
        "record": {"path": ELCENTRO, "format": "time-accel", "units": "g"},
        "loop": {"sensor_rate_hz": 50.0},
        "output": {"rate_hz": 50.0},
    })
    result = vines.run(scene)
    assert result.scene == "bare_from_python" and result.bare is None
    assert result.x.shape == (2689, 10)  # t = 0 to 53.76 s at 50 Hz


def test_modal_report():
    m = vines.modal(vines.Scene.load(os.path.join(SCENES, "elcentro_vines.toml")))
    assert m["frequency_hz"].shape == (10,) and m["mode_shapes"].shape == (10, 10)
    assert m["frequency_hz"][0] == pytest.approx(0.4946, abs=1e-4)  # README: f1 = 0.4946 Hz
    assert m["damping_ratio"][0] == pytest.approx(0.02, abs=1e-4)  # zeta1 = 2.00 %
    assert math.isclose(m["effective_mass_fraction"].sum(), 1.0, rel_tol=1e-9)
    assert np.all(np.diff(m["frequency_hz"]) > 0)


@pytest.mark.parametrize("overrides, key", [
    ({"vines.beta": 0.5}, "vines.beta"),
    ({"vines.law": "glue"}, "vines.law"),
    ({"loop.sensor_rate_hz": -1.0}, "loop.sensor_rate_hz"),
    ({"vines.no_such_key": 1}, "no_such_key"),
    ({"loop.sensor_rate_hz": "fast"}, "loop.sensor_rate_hz"),
])
def test_bad_overrides_name_the_key(vines_scene, overrides, key):
    with pytest.raises(vines.SceneError, match=key.replace(".", r"\.")):
        vines_scene.with_(overrides)


def test_bad_inputs_raise_with_their_name(tmp_path):
    with pytest.raises(vines.SceneError, match="missing.toml"):
        vines.Scene.load(tmp_path / "missing.toml")
    with pytest.raises(vines.SceneError, match="frame"):
        vines.Scene.from_dict({"frame": "table1"})
    with pytest.raises(TypeError, match="device.kind: a value of type object"):
        vines.Scene.from_dict({"frame": {"preset": "table1"}, "device": {"kind": object()}})
    with pytest.raises(vines.RecordError, match="sample 2 is not finite"):
        vines.Record([0.0, 0.1, float("nan"), 0.0], 0.01)
    with pytest.raises(vines.RecordError, match="dt"):
        vines.Record([0.0, 0.1], 0.0)
    with pytest.raises(vines.RecordError, match="no samples"):
        vines.Record([], 0.01)
    with pytest.raises(ValueError, match="units"):
        vines.Record([0.0, 0.1], 0.01, units="furlongs")
    with pytest.raises(vines.RecordError, match="nothing.at2"):
        vines.Record.load(tmp_path / "nothing.at2")


def test_the_python_guide_runs_as_written(capfd):
    with open(os.path.join(SOURCE, "docs", "python.md")) as f:
        guide = f.read()
    blocks = guide.split("```python\n")[1:]
    assert blocks, "no python block in docs/python.md"
    cwd = os.getcwd()
    os.chdir(SOURCE)
    try:
        for block in blocks:
            exec(compile(block[:block.index("```")], "docs/python.md", "exec"), {})
    finally:
        os.chdir(cwd)
    out = capfd.readouterr().out
    assert "ok" in out and "(5377,)" in out  # status; t at 100 rows a second of 53.76 s
    assert "['ok' 'ok' 'ok']" in out  # the sweep's three runs
    assert "\n1.0 " in out  # the loop's last step, at t = 1 s
    assert "vines.Scene('elcentro_vines' from 'data/scenes/elcentro_vines.toml', vines.beta=1.5)" in out
    assert "1.999 53.76 True" in out  # the state saved at 1.999 s, the run restored from it to the end
    # The shell line of the guide, as written (the package on PYTHONPATH as CTest sets it).
    line = next(l for l in guide.splitlines() if l.startswith("PYTHONPATH="))
    cmd = line.split(" ", 1)[1]
    res = subprocess.run(["bash", "-c", cmd], cwd=SOURCE, capture_output=True, text=True, check=True)
    assert res.stdout.startswith("vines.Result(scene 'elcentro_vines', status ok")


def test_a_sweep_equals_the_program(tmp_path, vines_scene):
    grid = {"vines.beta": [1.2, 1.35, 1.5], "loop.sensor_rate_hz": {"from": 200.0, "to": 500.0, "count": 2}}
    table = vines.sweep(vines_scene, grid=grid, threads=2)
    spec = tmp_path / "spec.toml"
    spec.write_text('[[study]]\nname = "py"\nscene = "%s"\n[study.grid]\n"vines.beta" = [1.2, 1.35, 1.5]\n'
                    '"loop.sensor_rate_hz" = {from = 200.0, to = 500.0, count = 2}\n' % vines_scene.origin)
    subprocess.run([VINES_EXE, "sweep", str(spec), "--out", str(tmp_path / "out"), "--no-progress"], check=True,
                   capture_output=True)
    with open(tmp_path / "out" / "results.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(table) == len(rows) == 6
    for key in ("vines.beta", "loop.sensor_rate_hz", "x_r", "E_r"):
        np.testing.assert_allclose(np.asarray(table[key], dtype=float), [float(r[key]) for r in rows], rtol=1e-9)
    assert list(np.asarray(table["status"])) == ["ok"] * 6
    # A run whose key is wrong fails alone, its error naming the key.
    bad = vines.sweep(vines_scene, grid={"vines.beta": [1.35, 0.5]})
    status = dict(zip(np.asarray(bad["vines.beta"]), np.asarray(bad["status"])))
    assert status == {1.35: "ok", 0.5: "failed"}
    failed = int(np.flatnonzero(np.asarray(bad["vines.beta"]) == 0.5)[0])
    assert "vines.beta" in bad["error"][failed] and math.isnan(bad["x_r"][failed])
    with pytest.raises(Exception, match="group_by"):
        vines.sweep(vines_scene, grid={"vines.beta": [1.35]}, group_by="vines.eps")


def test_a_loop_stepped_from_python_is_the_run(vines_run, vines_scene):
    result, _ = vines_run
    a = vines.samples(vines_scene)
    assert a.shape == (53761,)  # 53.76 s at 1 kHz, t = 0 first
    loop = vines.Loop(vines_scene)
    with pytest.raises(RuntimeError, match="reset"):
        loop.step(0.0)
    first = loop.reset(a[0])
    assert first.t == 0 and first.x.shape == (10,)
    every = round(vines_scene.sensor_rate_hz / vines_scene.output_rate_hz)
    for k in range(1, 2001):
        out = loop.step(a[k])
        if k % every == 0:
            np.testing.assert_array_equal(out.x, result.x[k // every])
    last = loop.run(a[2001:])
    np.testing.assert_array_equal(last.x, result.x[-1])
    assert last.particle_x == result.particle_x[-1]
    totals = loop.totals
    assert totals["peak_top_displacement_m"] == result.peak_top_displacement_m
    assert totals["contacts"] == result.contacts and totals["steps"] == 53760
    # A non-finite sample is held and counted, not propagated.
    held = loop.step(float("nan"))
    assert np.all(np.isfinite(held.x)) and loop.totals["bad_samples_held"] == 1
