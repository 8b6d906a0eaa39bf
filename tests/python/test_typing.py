"""The package is typed (PEP 561: py.typed, inline annotations, a stub of
the extension): mypy --strict passes on it and on a user's script, and
catches a user's type errors."""

import os
import subprocess
import sys
import textwrap

import pytest

import vines

PACKAGE = os.path.dirname(vines.__file__)

GOOD = """
import numpy as np
import numpy.typing as npt
import vines

scene: vines.Scene = vines.Scene.load("data/scenes/elcentro_vines.toml").with_({"vines.beta": np.float32(1.5)})
result: vines.Result = vines.run(scene, (np.zeros(100), 0.01))
peak: float = result.peak_top_displacement_m
top: npt.NDArray[np.float64] = result.x[:, -1]
loop = vines.Loop(scene)
step: vines.Step = loop.reset(0.0)
state: vines.LoopState = loop.state
loop.set_state(state, x=np.zeros(10))
print(vines.__version__, peak, top, step.t, vines.modal(scene)["frequency_hz"])
"""

BAD = """
import vines

scene = vines.Scene.load("data/scenes/elcentro_vines.toml")
loop = vines.Loop(scene)
t: str = loop.reset(0.0).t
loop.set_state(x=[0.0] * 10, particle_x="left")
vines.sweep(scene, threads="2")
"""


def mypy(*args):
    assert os.path.isfile(os.path.join(PACKAGE, "py.typed")) and os.path.isfile(os.path.join(PACKAGE, "_vines.pyi"))
    env = dict(os.environ, MYPYPATH=os.path.dirname(PACKAGE))
    return subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-incremental", "--cache-dir", os.devnull,
                           *args], capture_output=True, text=True, env=env)


def test_the_package_passes_mypy_strict():
    res = mypy("-p", "vines")
    assert res.returncode == 0, res.stdout + res.stderr


def test_a_users_script_is_checked(tmp_path):
    good, bad = tmp_path / "good.py", tmp_path / "bad.py"
    good.write_text(textwrap.dedent(GOOD))
    bad.write_text(textwrap.dedent(BAD))
    res = mypy(str(good))
    assert res.returncode == 0, res.stdout + res.stderr
    res = mypy(str(bad))
    assert res.returncode == 1
    assert 'Incompatible types in assignment (expression has type "float", variable has type "str")' in res.stdout
    assert 'Argument "particle_x" to "set_state" of "Loop" has incompatible type "str"' in res.stdout
    assert 'Argument "threads" to "sweep" has incompatible type "str"' in res.stdout
