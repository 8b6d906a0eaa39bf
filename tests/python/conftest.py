"""What the package's tests share: the checkout, its scenes, the El Centro
record and the program built beside the package (CTest sets
VINES_SOURCE_DIR, VINES_EXE and PYTHONPATH: tests/CMakeLists.txt)."""

import os

import numpy as np
import pytest

import vines

SOURCE = os.environ["VINES_SOURCE_DIR"]
VINES_EXE = os.environ["VINES_EXE"]
SCENES = os.path.join(SOURCE, "data", "scenes")
GROUND_MOTIONS = os.environ.get("VINES_GROUND_MOTIONS") or os.path.join(SOURCE, "..", "shared", "data",
                                                                        "ground_motions")
# 50 Hz as the studies run: fast runs that still have contacts.
STUDY = {"loop.sensor_rate_hz": 50.0, "output.rate_hz": 50.0}


def scene_path(name):
    return os.path.join(SCENES, name + ".toml")


@pytest.fixture(scope="session")
def vi():
    return vines.Scene.load(scene_path("elcentro_vines")).with_(STUDY)


@pytest.fixture(scope="session")
def tmd():
    return vines.Scene.load(scene_path("elcentro_tmd")).with_(STUDY)


@pytest.fixture(scope="session")
def bare():
    return vines.Scene.load(scene_path("elcentro_bare")).with_(STUDY)


def same_totals(a, b):
    """Two loops' totals equal, bit for bit (per-floor peaks as arrays)."""
    assert a.keys() == b.keys()
    for k in a:
        assert np.asarray(a[k]).tobytes() == np.asarray(b[k]).tobytes(), k


def same_result(a, b):
    """Two runs' summaries (but the wall time) and series equal, bit for bit."""
    untimed = set(a.summary) - {"wall_time_s"}
    assert {k: a.summary[k] for k in untimed} == {k: b.summary[k] for k in untimed}
    for name, arr in a.series.__dict__.items():
        assert arr.tobytes() == getattr(b.series, name).tobytes(), name
