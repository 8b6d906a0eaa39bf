"""What a user finds without reading the source: the version, docstrings,
reprs, dir(), a scene's values as dicts, tables of a predictable type, NaN
for what a device has not."""

import inspect
import math
import os
import re

import numpy as np
import pytest
from conftest import SOURCE

import vines


def test_the_version_is_the_projects():
    with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
        version = re.search(r"project\(vines VERSION ([0-9.]+)", f.read()).group(1)
    assert vines.__version__ == version


@pytest.mark.parametrize("obj", [vines.run, vines.sweep, vines.samples, vines.modal, vines.Scene.load,
                                 vines.Scene.from_dict, vines.Scene.with_, vines.Record, vines.Record.load,
                                 vines.Loop.set_state, vines.Loop.reset, vines.Loop.step, vines.Loop.run,
                                 vines.Result.to_frame])
def test_public_callables_have_numpydoc_sections(obj):
    doc = inspect.getdoc(obj)
    assert doc and ("Parameters\n----------" in doc or "Returns\n-------" in doc), obj


def test_a_result_lists_its_fields(vi):
    r = vines.run(vi)
    names = dir(r)
    for name in ("x_r", "E_r", "contacts", "status", "x", "particle_x", "to_frame", "summary", "bare"):
        assert name in names


def test_a_scene_reads_back_as_dicts_and_shows_its_overrides(vi):
    d = vi.to_dict()
    assert d["vines"]["beta"] == 1.35 and d["loop"]["sensor_rate_hz"] == 50.0 and d["device"]["kind"] == "vines"
    again = vines.Scene.from_dict(d, origin=vi.origin)
    assert again == vi
    assert repr(vi.with_({"vines.beta": 1.5})) == ("vines.Scene('elcentro_vines' from %r, loop.sensor_rate_hz=50.0, "
                                                   "output.rate_hz=50.0, vines.beta=1.5)" % vi.origin)
    assert vi.device == "vines"
    loop = vines.Loop(vi)
    assert repr(loop) == "vines.Loop('elcentro_vines', not reset)"
    loop.reset(0.0)
    loop.run(np.zeros(50))
    assert repr(loop) == "vines.Loop('elcentro_vines', t 1 s)"


def test_a_sweep_is_a_record_array_or_asked_for_a_frame(vi):
    import pandas
    rec = vines.sweep(vi, grid={"vines.beta": [1.2, 1.35]})
    assert isinstance(rec, np.recarray) and rec.dtype.names[:2] == ("vines.beta", "x_r")
    frame = vines.sweep(vi, grid={"vines.beta": [1.2, 1.35]}, as_frame=True)
    assert isinstance(frame, pandas.DataFrame)
    np.testing.assert_array_equal(frame["x_r"].to_numpy(), rec["x_r"])
    assert list(frame["status"]) == ["ok", "ok"]


def test_a_results_frame_holds_its_series(tmd):
    import pandas
    r = vines.run(tmd)
    f = r.to_frame(bare=True)
    assert isinstance(f, pandas.DataFrame)
    assert f.index.name == "t" and np.array_equal(f.index.to_numpy(), r.t)
    assert f.shape[0] == len(r.t)
    np.testing.assert_array_equal(f["x10"].to_numpy(), r.x[:, 9])
    np.testing.assert_array_equal(f["drift3"].to_numpy(), r.drift[:, 2])
    np.testing.assert_array_equal(f["tmd_x"].to_numpy(), r.tmd_x)
    np.testing.assert_array_equal(f["bare_x10"].to_numpy(), r.bare.x[:, 9])
    assert "particle_x" not in f and "mode" not in f  # a TMD has no sphere


def test_channels_a_device_has_not_are_nan(tmd, bare, vi):
    t, b, v = vines.run(tmd), vines.run(bare), vines.run(vi)
    for name in ("particle_x", "particle_v", "wall_left", "wall_right", "contact_force", "mode"):
        assert np.all(np.isnan(getattr(t, name))) and np.all(np.isnan(getattr(b, name)))
        assert np.all(np.isnan(getattr(t.bare, name))) and np.all(np.isfinite(getattr(v, name)))
    for name in ("tmd_x", "tmd_v"):
        assert np.all(np.isnan(getattr(v, name))) and np.all(np.isfinite(getattr(t, name)))
        assert np.all(np.isnan(getattr(v.bare, name)))
    step = vines.Loop(tmd).reset(0.0)
    assert math.isnan(step.particle_x) and step.tmd_x == 0.0
