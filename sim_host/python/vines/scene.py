"""Scenes: a checked scene file (data/scenes/README.md) as an immutable
Python object."""

from __future__ import annotations

import os
from typing import Any, Dict, Mapping, Optional, Tuple

from . import _vines
from ._convert import PathLike, path_of, plain, plain_dict


class Scene:
    """A checked scene: frame, device, contact law, record, loop and
    outputs (data/scenes/README.md). Immutable: `with_` returns a new scene.

    Make one with `Scene.load`, `Scene.from_dict` or `Scene.from_toml`.
    Equal scenes (same origin and values) compare equal; a scene pickles
    and deep-copies as its TOML text, its origin and its overrides.
    """

    __slots__ = ("_impl", "_overrides")

    def __init__(self, impl: _vines.Scene, overrides: Optional[Dict[str, Any]] = None) -> None:
        self._impl = impl
        self._overrides: Dict[str, Any] = dict(overrides or {})

    @classmethod
    def load(cls, path: PathLike) -> "Scene":
        """The scene file at `path`.

        Parameters
        ----------
        path : str or os.PathLike
            A scene file; relative record paths in it resolve against its
            folder, then the ground-motions folder.

        Raises
        ------
        SceneError
            The file is missing or a key in it is wrong (the message names it).
        """
        return cls(_vines.Scene.load(path_of(path, "vines.Scene.load")))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], origin: str = "<dict>") -> "Scene":
        """A scene from nested mappings, as the TOML file would hold them.

        Parameters
        ----------
        d : mapping
            ``{"frame": {"preset": "table1"}, "device": {"kind": "vines"}, ...}``;
            numpy scalars and arrays are taken as the numbers they hold.
        origin : str
            Names the scene in messages; relative record paths resolve
            against its folder.
        """
        return cls(_vines.Scene.from_dict(plain_dict(d, "vines.Scene.from_dict: " + origin), origin))

    @classmethod
    def from_toml(cls, text: str, origin: str = "<toml>") -> "Scene":
        """A scene from TOML text; `origin` names it in messages."""
        if not isinstance(text, str):
            raise TypeError("vines.Scene.from_toml: TOML text (str), not %s" % type(text).__name__)
        return cls(_vines.Scene.from_toml(text, origin))

    def with_(self, overrides: Optional[Mapping[str, Any]] = None, **kwargs: Any) -> "Scene":
        """A copy with dotted keys set, as in study specs.

        Parameters
        ----------
        overrides : mapping, optional
            ``{"vines.beta": 1.5, "loop.sensor_rate_hz": 200.0}``.
        **kwargs
            Top-level sections' keys with ``__`` for the dot:
            ``scene.with_(vines__beta=1.5)``.

        Raises
        ------
        SceneError
            A key is unknown or a value is out of range (named in the message).
        TypeError
            A value is not a number, string, list or dict.
        """
        merged = dict(overrides or {})
        merged.update({k.replace("__", "."): v for k, v in kwargs.items()})
        values = {str(k): plain(v, "%s: %s" % (self.origin, k)) for k, v in merged.items()}
        return Scene(self._impl.with_(values), {**self._overrides, **values})

    def to_toml(self) -> str:
        """The scene as TOML text (loadable with `Scene.from_toml`)."""
        return self._impl.to_toml()

    def to_dict(self) -> Dict[str, Any]:
        """The scene's tables as nested dicts (`Scene.from_dict` takes them back)."""
        return self._impl.to_dict()

    @property
    def overrides(self) -> Dict[str, Any]:
        """The dotted keys `with_` has set since the scene was loaded (a copy)."""
        return dict(self._overrides)

    @property
    def name(self) -> str:
        """[scene] name."""
        return self._impl.name

    @property
    def origin(self) -> str:
        """The file (or origin) it came from."""
        return self._impl.origin

    @property
    def device(self) -> str:
        """The device kind: "vines", "tmd" or "none"."""
        return self._impl.device

    @property
    def stories(self) -> int:
        """Number of stories of the frame."""
        return self._impl.stories

    @property
    def sensor_rate_hz(self) -> float:
        """The loop's sample rate [Hz]."""
        return self._impl.sensor_rate_hz

    @property
    def output_rate_hz(self) -> float:
        """The rate of the series a run returns [Hz]."""
        return self._impl.output_rate_hz

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Scene):
            return NotImplemented
        return (self.origin, self.to_toml()) == (other.origin, other.to_toml())

    def __hash__(self) -> int:
        return hash((self.origin, self.to_toml()))

    def __reduce__(self) -> Tuple[Any, ...]:
        return (_restore, (self.to_toml(), self.origin, self._overrides))

    def __repr__(self) -> str:
        text = "vines.Scene(%r from %r" % (self.name, self.origin)
        if self._overrides:
            text += ", " + ", ".join("%s=%r" % kv for kv in self._overrides.items())
        return text + ")"


def _restore(text: str, origin: str, overrides: Dict[str, Any]) -> Scene:
    return Scene(_vines.Scene.from_toml(text, origin), overrides)


def as_scene(scene: Any, what: str) -> Scene:
    """A Scene, or the scene file at a path; TypeError otherwise."""
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, (str, os.PathLike)):
        return Scene.load(scene)
    raise TypeError("%s: a vines.Scene or a scene file's path, not %s" % (what, type(scene).__name__))
