"""The scene's device run stepped from Python one sample at a time, as a
digital twin is fed; its state read, saved and set."""

from __future__ import annotations

from typing import Any, Dict, Mapping, Optional, Tuple

import numpy as np
import numpy.typing as npt

from . import _vines
from ._convert import real, samples_array
from .result import blank_absent
from .scene import Scene, as_scene


class Step:
    """One step's outputs: t, ag; x, v, acc, drift (one value per floor);
    elastic_energy; particle_x, particle_v, wall_left, wall_right,
    contact_force, mode (VI NES); tmd_x, tmd_v (TMD). Units as in
    `Series`; NaN for what the device has not."""

    t: float
    ag: float
    x: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    acc: npt.NDArray[np.float64]
    drift: npt.NDArray[np.float64]
    elastic_energy: float
    particle_x: float
    particle_v: float
    wall_left: float
    wall_right: float
    contact_force: float
    mode: float
    tmd_x: float
    tmd_v: float

    def __init__(self, d: Mapping[str, Any]) -> None:
        self.__dict__.update(d)

    def __repr__(self) -> str:
        return "vines.Step(t %.6g s, top floor %.6g m)" % (self.t, self.x[-1])


class LoopState:
    """A loop's whole state at one time, from `Loop.state`: restored by
    `Loop.set_state` bit for bit (the run then goes on as it would have).

    Attributes
    ----------
    t : float
        The time [s].
    x, v : ndarray
        Floor displacements and velocities relative to the ground [m, m/s].
    particle_x, particle_v : float
        VI NES sphere (NaN without one) [m, m/s].
    tmd_x, tmd_v : float
        TMD mass (NaN without one) [m, m/s].
    """

    __slots__ = ("data", "t", "x", "v", "particle_x", "particle_v", "tmd_x", "tmd_v")

    def __init__(self, data: bytes, step: Mapping[str, Any]) -> None:
        self.data = bytes(data)
        self.t: float = step["t"]
        self.x: npt.NDArray[np.float64] = np.array(step["x"])
        self.v: npt.NDArray[np.float64] = np.array(step["v"])
        self.particle_x: float = step["particle_x"]
        self.particle_v: float = step["particle_v"]
        self.tmd_x: float = step["tmd_x"]
        self.tmd_v: float = step["tmd_v"]

    def __reduce__(self) -> Tuple[Any, ...]:
        fields = {k: getattr(self, k) for k in self.__slots__ if k != "data"}
        return (LoopState, (self.data, fields))

    def __repr__(self) -> str:
        return "vines.LoopState(t %.6g s, top floor %.6g m)" % (self.t, self.x[-1])


class Loop:
    """The scene's device run stepped one sample at a time: the engine
    `vines run` uses, built once.

    Parameters
    ----------
    scene : Scene or path
        The scene (its device, frame, contact law and loop settings).

    Examples
    --------
    >>> loop = vines.Loop(scene)
    >>> a = vines.samples(scene)
    >>> first = loop.reset(a[0])
    >>> for a_g in a[1:]:
    ...     out = loop.step(a_g)      # out.x[-1]: the top floor now

    A non-finite sample is held (the loop's guard, counted in totals). A
    Loop pickles and deep-copies with its state.
    """

    def __init__(self, scene: Any) -> None:
        self.scene: Scene = as_scene(scene, "vines.Loop")
        self._impl = _vines.Loop(self.scene._impl)

    def _step(self, d: Dict[str, Any]) -> Step:
        return Step(blank_absent(d, self.scene.device))

    def reset(self, a0: float = 0.0) -> Step:
        """Back to t = 0, in the scene's initial conditions.

        Parameters
        ----------
        a0 : float
            The ground acceleration at t = 0 [m/s^2].

        Returns
        -------
        Step
            The outputs at t = 0.
        """
        return self._step(self._impl.reset(real(a0, "vines.Loop.reset: a0")))

    def step(self, a_g: float) -> Step:
        """One sensor period on.

        Parameters
        ----------
        a_g : float
            The next ground acceleration sample [m/s^2]; a non-finite one
            is held (the last good one used) and counted.

        Returns
        -------
        Step
            The outputs at the new time.

        Raises
        ------
        RuntimeError
            Before `reset` (or `set_state` with a saved state).
        """
        return self._step(self._impl.step(real(a_g, "vines.Loop.step: a_g")))

    def run(self, samples: npt.ArrayLike) -> Step:
        """Steps through many samples, the loop in C++ with the GIL released.

        Parameters
        ----------
        samples : array_like
            Ground acceleration samples [m/s^2], one a sensor period.

        Returns
        -------
        Step
            The last step's outputs.
        """
        return self._step(self._impl.run(samples_array(samples, "vines.Loop.run: samples")))

    @property
    def state(self) -> LoopState:
        """The whole state now (see `LoopState`)."""
        return LoopState(self._impl.state(), self._step(self._impl.now()).__dict__)

    def set_state(self, state: Optional[LoopState] = None, *, x: Optional[npt.ArrayLike] = None,
                  v: Optional[npt.ArrayLike] = None, particle_x: Optional[float] = None,
                  particle_v: Optional[float] = None, tmd_x: Optional[float] = None,
                  tmd_v: Optional[float] = None) -> Step:
        """Sets the loop's state: a saved one, the physical one, or both.

        Parameters
        ----------
        state : LoopState, optional
            A state from `Loop.state` of a loop of the same scene: restored
            bit for bit (time, peaks, counters, energy ledger and all).
        x, v : array_like, optional
            Every floor's displacement / velocity relative to the ground
            [m, m/s] (an estimator's update); the time, peaks and counters
            are kept, the energy the change stores counts as put in.
        particle_x, particle_v : float, optional
            The VI NES sphere [m, m/s]; it must lie between the walls (it
            is then in free flight).
        tmd_x, tmd_v : float, optional
            The TMD mass [m, m/s].

        Returns
        -------
        Step
            The outputs of the state set.

        Raises
        ------
        ValueError
            A state of another scene, a particle past a wall, a value of the
            wrong shape, or a field the device has not.
        """
        if state is not None:
            if not isinstance(state, LoopState):
                raise TypeError("vines.Loop.set_state: a vines.LoopState, not %s" % type(state).__name__)
            self._impl.load_state(state.data)
        values: Dict[str, Any] = {}
        for k, floors in (("x", x), ("v", v)):
            if floors is not None:
                a = np.asarray(floors, dtype=float)
                if a.shape != (self.scene.stories,):
                    raise ValueError("vines.Loop.set_state: %s: one value a floor (%d), not shape %s"
                                     % (k, self.scene.stories, a.shape))
                values[k] = a
        for k, value in (("particle_x", particle_x), ("particle_v", particle_v), ("tmd_x", tmd_x),
                         ("tmd_v", tmd_v)):
            if value is not None:
                values[k] = float(value)
        if values:
            self._impl.set_physical(values)
        return self._step(self._impl.now())

    @property
    def totals(self) -> Dict[str, Any]:
        """Running results: peak_top_displacement_m, t_peak_top_s,
        per-floor peaks, elastic_energy_integral, contacts, max_overlap_m,
        steps and the guards' counts."""
        return self._impl.totals

    def __getstate__(self) -> Dict[str, Any]:
        return {"scene": self.scene, "state": self._impl.state() if self._impl.started else None}

    def __setstate__(self, saved: Dict[str, Any]) -> None:
        self.__init__(saved["scene"])  # type: ignore[misc]
        if saved["state"] is not None:
            self._impl.load_state(saved["state"])

    def __repr__(self) -> str:
        where = "t %.6g s" % self._impl.now()["t"] if self._impl.started else "not reset"
        return "vines.Loop(%r, %s)" % (self.scene.name, where)
