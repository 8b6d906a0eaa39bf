"""vines from Python: the firmware core and host library of the `vines`
program, with scenes, records and results as Python objects and numpy arrays.

    import vines
    scene = vines.Scene.load("data/scenes/elcentro_vines.toml")
    result = vines.run(scene.with_({"vines.beta": 1.5}))
    print(result.x_r, result.E_r, result.x.shape)

Scene, Record, run, sweep, Loop (stepping sample by sample), samples, modal:
docs/python.md. Numbers may be numpy scalars and lists numpy arrays
anywhere; scenes, records, loops and results pickle.

Every check and message is the command line's: a bad scene raises
vines.SceneError (a ValueError) naming the key, a bad record
vines.RecordError naming the file or array; an argument of the wrong type
a TypeError naming what was expected.
"""

from ._vines import RecordError, SceneError, __version__
from .loop import Loop, LoopState, Step
from .record import Record
from .result import Result, Series
from .scene import Scene
from .study import modal, run, samples, sweep

__all__ = ["Scene", "Record", "Result", "Series", "Loop", "LoopState", "Step", "run", "samples", "sweep", "modal",
           "SceneError", "RecordError", "__version__"]
