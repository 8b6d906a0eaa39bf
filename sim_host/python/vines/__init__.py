"""vines from Python: the firmware core and host library of the `vines`
program, with scenes, records and results as Python objects and numpy arrays.

    import vines
    scene = vines.Scene.load("data/scenes/elcentro_vines.toml")
    result = vines.run(scene.with_({"vines.beta": 1.5}))
    print(result.x_r, result.E_r, result.x.shape)

Scene, Record, run, sweep, Loop (stepping sample by sample), samples, modal:
docs/python.md.

Every check and message is the command line's: a bad scene raises
vines.SceneError (a ValueError) naming the key, a bad record
vines.RecordError naming the file or array.
"""

import json as _json

import numpy as _np

from . import _vines
from ._vines import RecordError, SceneError

__all__ = ["Scene", "Record", "Result", "Loop", "run", "samples", "sweep", "modal", "SceneError", "RecordError"]


class Scene:
    """A checked scene (data/scenes/README.md): frame, device, contact law,
    record, loop and outputs. Immutable: with_() returns a new scene."""

    def __init__(self, impl):
        self._impl = impl

    @classmethod
    def load(cls, path):
        """The scene file at `path` (relative record paths resolve against it)."""
        return cls(_vines.Scene.load(str(path)))

    @classmethod
    def from_dict(cls, d, origin="<dict>"):
        """A scene from nested dicts, as the TOML file would hold them:
        {"frame": {"preset": "table1"}, "device": {"kind": "vines"}, ...}."""
        return cls(_vines.Scene.from_dict(d, origin))

    @classmethod
    def from_toml(cls, text, origin="<toml>"):
        """A scene from TOML text; `origin` names it in messages."""
        return cls(_vines.Scene.from_toml(text, origin))

    def with_(self, overrides=None, **kwargs):
        """A copy with dotted keys set, as in study specs:
        scene.with_({"vines.beta": 1.5, "loop.sensor_rate_hz": 200.0}).
        Keyword arguments name top-level sections' keys with "__" for the
        dot: scene.with_(vines__beta=1.5)."""
        merged = dict(overrides or {})
        merged.update({k.replace("__", "."): v for k, v in kwargs.items()})
        return Scene(self._impl.with_(merged))

    def to_toml(self):
        """The scene as TOML text (loadable with Scene.from_toml)."""
        return self._impl.to_toml()

    name = property(lambda self: self._impl.name, doc="[scene] name")
    origin = property(lambda self: self._impl.origin, doc="the file (or origin) it came from")
    stories = property(lambda self: self._impl.stories)
    sensor_rate_hz = property(lambda self: self._impl.sensor_rate_hz)
    output_rate_hz = property(lambda self: self._impl.output_rate_hz)

    def __repr__(self):
        return "vines.Scene(%r from %r)" % (self.name, self.origin)


class Record:
    """A ground-motion record in m/s^2 at a uniform step dt [s].

    Record(acc, dt, units="g", t0=0.0) takes samples (a 1-D array, sample i
    at t0 + i dt); Record.load(path) reads a file the way
    `vines run --record` does."""

    def __init__(self, acc, dt, units="g", t0=0.0, name="<array>", _impl=None):
        self._impl = _impl if _impl is not None else _vines.Record.from_array(
            _np.asarray(acc, dtype=float), float(dt), float(t0), units, name)

    @classmethod
    def load(cls, path, format="auto", units="g", column=1, dt=0.0):
        """format: auto, at2, time-accel or accel (values only: give dt);
        units of a columns file: g, m/s2 or cm/s2 (an AT2 header says its own);
        column: the acceleration column of a time-accel file (1 = first)."""
        return cls(None, None, _impl=_vines.Record.load(str(path), format, units, int(column), float(dt)))

    path = property(lambda self: self._impl.path)
    dt = property(lambda self: self._impl.dt, doc="sample step [s]")
    t0 = property(lambda self: self._impl.t0, doc="time of the first sample [s]")
    acc = property(lambda self: self._impl.acc, doc="samples [m/s^2] (a copy)")
    pga = property(lambda self: self._impl.pga, doc="peak ground acceleration [m/s^2]")

    @property
    def t(self):
        """Sample times [s]."""
        return self._impl.t0 + self.dt * _np.arange(len(self._impl))

    def __len__(self):
        return len(self._impl)

    def __repr__(self):
        return "vines.Record(%r, %d points, dt %g s)" % (self.path, len(self), self.dt)


class Series:
    """Time series at the scene's output rate: t [s], ag [m/s^2]; x, v, acc,
    drift (rows x stories; relative displacement [m], velocity [m/s],
    absolute acceleration [m/s^2], story drift [m]); elastic_energy (E_e so
    far) [J s]; VI NES particle_x, particle_v, wall_left, wall_right [m, m/s],
    contact_force [N], mode; TMD tmd_x, tmd_v."""

    def __init__(self, arrays):
        self.__dict__.update(arrays)

    def __repr__(self):
        return "vines.Series(%d rows: %s)" % (len(self.t), ", ".join(sorted(self.__dict__)))


class Result:
    """A run: the fields of summary.json as attributes (x_r, E_r,
    peak_top_displacement_m, contacts, status, counters, modal, ...; the
    summary dict itself is .summary), the device run's series as
    attributes too (result.t, result.x, result.particle_x, ...) and the bare
    frame's as result.bare (None without a device)."""

    def __init__(self, raw):
        self.summary = _json.loads(raw["summary"])
        self.series = Series(raw["series"])
        self.bare = Series(raw["bare_series"]) if "bare_series" in raw else None

    def __getattr__(self, name):
        summary = self.__dict__.get("summary", {})
        if name in summary:
            return summary[name]
        series = self.__dict__.get("series")
        if series is not None and name in series.__dict__:
            return series.__dict__[name]
        raise AttributeError("vines.Result has no field %r" % name)

    @property
    def degraded(self):
        return self.summary["status"] != "ok"

    def __repr__(self):
        s = self.summary
        parts = ["scene %r" % s["scene"], "status %s" % s["status"],
                 "peak %.6g m" % s["peak_top_displacement_m"]]
        if "x_r" in s:
            parts += ["x_r %.4g" % s["x_r"], "E_r %.4g" % s["E_r"]]
        return "vines.Result(" + ", ".join(parts) + ")"


def run(scene, record=None):
    """Runs `scene` on its own record, or on `record` (a vines.Record: of it,
    only the scene's scale or pga_g and duration_s apply, as with
    `vines run --record`). With a device the bare frame runs too (x_r, E_r).
    The loop runs with the GIL released."""
    return Result(_vines.run(scene._impl, None if record is None else record._impl))


def samples(scene, record=None):
    """The ground acceleration a run of `scene` steps through [m/s^2]: its
    record (or `record`) scaled as the scene says and resampled to the sensor
    rate, sample k at t = k / sensor_rate_hz."""
    return _vines.samples(scene._impl, None if record is None else record._impl)


class Step:
    """One step's outputs: t, ag; x, v, acc, drift (one value per floor);
    elastic_energy; particle_x, particle_v, wall_left, wall_right,
    contact_force, mode (VI NES); tmd_x, tmd_v (TMD). Units as in Series."""

    def __init__(self, d):
        self.__dict__.update(d)

    def __repr__(self):
        return "vines.Step(t %.6g s, top floor %.6g m)" % (self.t, self.x[-1])


class Loop:
    """The scene's device run stepped from Python one sample at a time, as a
    digital twin is fed: the engine `vines run` uses, built once.

        loop = vines.Loop(scene)
        a = vines.samples(scene)
        loop.reset(a[0])
        for a_g in a[1:]:
            out = loop.step(a_g)      # out.x[-1]: the top floor now

    A non-finite sample is held (the loop's guard, counted in totals)."""

    def __init__(self, scene):
        self.scene = scene
        self._impl = _vines.Loop(scene._impl)

    def reset(self, a0=0.0):
        """Back to t = 0 (the scene's initial conditions), ground acceleration a0."""
        return Step(self._impl.reset(float(a0)))

    def step(self, a_g):
        """One sensor period to the next sample a_g [m/s^2]; its outputs."""
        return Step(self._impl.step(float(a_g)))

    def run(self, samples):
        """Steps through every sample (the loop in C++, the GIL released);
        the last step's outputs."""
        return Step(self._impl.run(_np.asarray(samples, dtype=float)))

    @property
    def totals(self):
        """Running results: peak_top_displacement_m, t_peak_top_s, per-floor
        peaks, elastic_energy_integral, contacts, max_overlap_m, steps and
        the guards' counts."""
        return self._impl.totals


def sweep(scene, grid=None, set=None, cases=None, group_by=None, threads=0):
    """Runs `scene` as `vines sweep` runs a study (data/studies/README.md):
    grid {"section.key": [values] or {"from", "to", "step" | "count",
    "scale"}}, set {"section.key": value} fixed, cases [{"section.key":
    value, ...}, ...] paired; the runs are the cases times the grid, on
    `threads` C++ threads (0: every core) with the GIL released (Ctrl-C
    stops them). Returns one row per run, in results.csv's order: the keys'
    values (results.csv's column names), x_r, E_r, peak_top_displacement_m,
    elastic_energy_integral, contacts, status (ok, degraded or failed),
    degraded_reasons, error; a pandas DataFrame when pandas is installed,
    else a numpy record array."""
    raw = _vines.sweep(scene._impl, dict(grid or {}), dict(set or {}), list(cases or []), group_by or "",
                       int(threads))
    columns = {key: _np.asarray(values) for key, values in zip(raw["keys"], raw["values"])}
    for name in ("x_r", "E_r", "peak_top_displacement_m", "elastic_energy_integral", "contacts"):
        columns[name] = raw[name]
    for name in ("status", "degraded_reasons", "error"):
        columns[name] = _np.asarray(raw[name], dtype=str)
    try:
        import pandas
    except ImportError:
        return _np.rec.fromarrays(list(columns.values()), names=list(columns))
    return pandas.DataFrame(columns)


def modal(scene):
    """The frame's modes (with the scene's device floor): frequency_hz,
    damping_ratio, participation_factor, effective_mass_kg,
    effective_mass_fraction (arrays over the modes), mode_shapes (modes x
    floors), total_mass_kg."""
    m = _json.loads(_vines.modal(scene._impl))
    return {k: (v if isinstance(v, float) else _np.asarray(v)) for k, v in m.items()}
