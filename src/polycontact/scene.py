"""Scenes: two or more moving bodies and a time window, read from JSON.

The format (design.md §4)::

    {"t_max": 20, "time_tolerance": 1e-4, "description": "...",
     "bodies": [{"name": "red", "vertices": [[x, y], ...], "holes": [[[x, y], ...]],
                 "velocity": [vx, vy], "acceleration": [ax, ay],
                 "angular_velocity": w | "angular_velocity_deg": w,
                 "angular_acceleration": al | "angular_acceleration_deg": al}, ...]}

``t_max`` and each body's ``vertices`` are required; ``time_tolerance``,
``description`` and every motion key are optional (zero motion by default). Angular
quantities are radians (per second, per second squared) unless the key ends in
``_deg``. Unknown keys, wrong types, non-finite numbers, duplicate names and fewer than
two bodies are refused with an :class:`~polycontact.InvalidSceneError` naming the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from collections.abc import Mapping
from typing import Any

from ._checks import shown
from ._json import load_json
from .broad_phase import check_reach
from .errors import InvalidSceneError, InvalidShapeError
from .impact import time_of_impact
from .impacts import PairImpact, PairImpacts, first_impact, first_impacts
from .limits import MAX_ITERATIONS, SAMPLES, TIME_TOLERANCE
from .motion import Motion
from .shape import Shape, as_shape

__all__ = ["SceneBody", "Scene", "load_scene"]

_TOP_KEYS = {"t_max", "bodies", "time_tolerance", "description"}
_BODY_KEYS = {
    "name", "vertices", "holes", "velocity", "acceleration",
    "angular_velocity", "angular_velocity_deg",
    "angular_acceleration", "angular_acceleration_deg",
}


@dataclass(frozen=True)
class SceneBody:
    """One body of a :class:`Scene`: a named shape and its motion.

    Attributes
    ----------
    name : str
        Unique in its scene (``"body<k>"`` when the file gives none).
    shape : Shape
        The body at t = 0.
    motion : Motion
        How it moves about its area centroid.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> body = SceneBody("red", Shape([(0, 0), (1, 0), (0, 1)]), Motion(velocity=(1, 0)))
    >>> body.name, body.motion.velocity
    ('red', (1.0, 0.0))
    """

    name: str
    shape: Shape
    motion: Motion


@dataclass(frozen=True)
class Scene:
    """Bodies moving over ``[0, t_max]``, as a scene file describes them.

    Attributes
    ----------
    bodies : tuple of SceneBody
        Two or more, in file order; :class:`~polycontact.PairImpact` entries number
        them by their index here.
    t_max : float
        End of the time window.
    time_tolerance : float or None
        The file's time tolerance (the default of :meth:`first_impact` and
        :meth:`impacts`), None when it gives none.
    description : str or None

    Examples
    --------
    >>> scene = Scene.from_dict({"t_max": 5, "bodies": [
    ...     {"name": "a", "vertices": [[0, 0], [1, 0], [1, 1], [0, 1]], "velocity": [1, 0]},
    ...     {"name": "b", "vertices": [[3, 0], [4, 0], [4, 1], [3, 1]]}]})
    >>> i, j, impact = scene.first_impact()
    >>> scene.bodies[i].name, scene.bodies[j].name, round(impact.time, 3)
    ('a', 'b', 2.0)
    """

    bodies: tuple[SceneBody, ...]
    t_max: float
    time_tolerance: float | None = None
    description: str | None = None

    @classmethod
    def from_dict(cls, data: object, *, repair: bool = False) -> Scene:
        """Build a scene from parsed JSON (lists or tuples).

        Parameters
        ----------
        data : dict
            The scene, in the format of the module docstring (anything else is
            refused with an :class:`~polycontact.InvalidSceneError`).
        repair : bool, default False
            Passed to :func:`~polycontact.shape.as_shape` for every body.

        Returns
        -------
        Scene

        Raises
        ------
        InvalidSceneError
            A bad key, named (``bodies[1].velocity: ...``).

        Examples
        --------
        >>> sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
        >>> Scene.from_dict({"t_max": 2, "bodies": [{"vertices": sq},
        ...                  {"vertices": sq, "velocity": [0, 3]}]}).t_max
        2.0
        """
        if not isinstance(data, dict):
            raise InvalidSceneError(f"expected a JSON object, got {type(data).__name__}")
        _no_unknown(data, _TOP_KEYS, "")
        t_max = _number(_required(data, "t_max", ""), "t_max")
        if t_max < 0:
            raise InvalidSceneError(f"t_max: expected a number >= 0, got {t_max}")
        tol = None
        if "time_tolerance" in data:
            tol = _number(data["time_tolerance"], "time_tolerance")
            if tol <= 0:
                raise InvalidSceneError(f"time_tolerance: expected a number > 0, got {tol}")
        desc = data.get("description")
        if desc is not None and not isinstance(desc, str):
            raise InvalidSceneError("description: expected a string")
        bodies = _required(data, "bodies", "")
        if not isinstance(bodies, list):
            raise InvalidSceneError(f"bodies: expected a list, got {type(bodies).__name__}")
        if len(bodies) < 2:
            raise InvalidSceneError(f"bodies: expected at least two bodies, got {len(bodies)}")
        parsed = tuple(_body(b, i, repair, t_max) for i, b in enumerate(bodies))
        names = [b.name for b in parsed]
        for i, name in enumerate(names):
            if name in names[:i]:
                raise InvalidSceneError(f"bodies[{i}].name: duplicate name {name!r}")
        return cls(parsed, t_max, tol, desc)

    def first_impact(
        self,
        *,
        method: str = "exact",
        time_tolerance: float | None = None,
        samples: int = SAMPLES,
        max_iterations: int = MAX_ITERATIONS,
        threads: int | None = None,
    ) -> PairImpact:
        """The earliest event among all pairs of bodies.

        A pair already penetrating at t = 0, then the earliest collision; a pair whose
        search ran out of iterations before that time is reported instead (no
        verdict). Without collision, the pair that touched first, else the first pair
        (with its :class:`~polycontact.Impact` saying that nothing happened). The order
        of :func:`polycontact.first_impact`, which it uses for three bodies or more.

        Parameters
        ----------
        method, samples, max_iterations, threads
            As for :func:`polycontact.first_impacts`.
        time_tolerance : float, optional
            Default the scene's :attr:`time_tolerance`, else
            :data:`~polycontact.limits.TIME_TOLERANCE`.

        Returns
        -------
        PairImpact
            ``(i, j, impact)``, ``i < j`` indices into :attr:`bodies`.

        Examples
        --------
        >>> from polycontact import Motion, Shape
        >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> scene = Scene((SceneBody("a", sq, Motion(velocity=(1, 0))),
        ...                SceneBody("b", sq.moved((0, 3)), Motion())), t_max=5)
        >>> i, j, impact = scene.first_impact()
        >>> i, j, impact.status.value
        (0, 1, 'no-hit')
        """
        tol = self._time_tolerance(time_tolerance)
        if len(self.bodies) >= 3:
            # only the pairs whose swept bounds meet are searched (the same answer as
            # every pair's time_of_impact)
            ev = first_impact([b.shape for b in self.bodies], [b.motion for b in self.bodies],
                              t_max=self.t_max, method=method, time_tolerance=tol,
                              samples=samples, max_iterations=max_iterations, threads=threads)
            if ev is not None:
                return ev
        a, b = self.bodies[0], self.bodies[1]  # two bodies, or nothing meets: the first pair
        return PairImpact(0, 1, time_of_impact(
            a.shape, a.motion, b.shape, b.motion, t_max=self.t_max, method=method,
            time_tolerance=tol, samples=samples, max_iterations=max_iterations))

    def impacts(
        self,
        *,
        method: str = "exact",
        time_tolerance: float | None = None,
        samples: int = SAMPLES,
        max_iterations: int = MAX_ITERATIONS,
        threads: int | None = None,
    ) -> PairImpacts:
        """Every pair that meets within ``[0, t_max]`` (touches, penetrates, or has no
        verdict), sorted by time: what ``polycontact collide --all`` lists.

        Parameters
        ----------
        method, time_tolerance, samples, max_iterations, threads
            As for :meth:`first_impact`.

        Returns
        -------
        PairImpacts
            ``(i, j, impact)`` records, ``i < j`` indices into :attr:`bodies`, as
            :func:`polycontact.first_impacts` gives them.

        Examples
        --------
        >>> from polycontact import Motion, Shape
        >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> scene = Scene((SceneBody("a", sq, Motion(velocity=(1, 0))),
        ...                SceneBody("b", sq.moved((3, 0)), Motion()),
        ...                SceneBody("c", sq.moved((1.5, 1)), Motion())), t_max=5)
        >>> [(scene.bodies[i].name, scene.bodies[j].name, imp.status.value)
        ...  for i, j, imp in scene.impacts()]
        [('a', 'c', 'no-hit'), ('a', 'b', 'hit')]
        """
        return first_impacts([b.shape for b in self.bodies], [b.motion for b in self.bodies],
                             t_max=self.t_max, method=method,
                             time_tolerance=self._time_tolerance(time_tolerance),
                             samples=samples, max_iterations=max_iterations, threads=threads)

    def _time_tolerance(self, asked: float | None) -> float:
        """The time tolerance of a search: the one asked for, else the scene's, else
        the default."""
        if asked is not None:
            return asked
        return TIME_TOLERANCE if self.time_tolerance is None else self.time_tolerance


def load_scene(path: str | Path | Mapping[str, Any], *, repair: bool = False) -> Scene:
    """Read a scene JSON file, or take its parsed content (format in the module docstring).

    Parameters
    ----------
    path : str, Path or mapping
        The file's path, or the parsed scene itself (as :meth:`Scene.from_dict`).
    repair : bool, default False
        Passed to :func:`polycontact.shape.as_shape` for every body.

    Returns
    -------
    Scene

    Raises
    ------
    InvalidSceneError
        Unreadable file, invalid JSON, or a bad key; the message starts with the file
        name and names the key (``bodies[1].velocity: ...``).
    TypeError
        ``path`` is neither a path nor a mapping.

    Examples
    --------
    >>> sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    >>> scene = load_scene({"t_max": 1, "bodies": [{"vertices": sq},
    ...                     {"vertices": [[x + 2, y] for x, y in sq]}]})
    >>> [b.name for b in scene.bodies]
    ['body0', 'body1']
    """
    if isinstance(path, Mapping):
        return Scene.from_dict(dict(path), repair=repair)
    if not isinstance(path, (str, Path)):
        raise TypeError(f"path: expected a path or a mapping, got {type(path).__name__}")
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise InvalidSceneError(f"{path}: cannot read ({exc.strerror})") from None
    except UnicodeDecodeError as exc:
        raise InvalidSceneError(f"{path}: not a JSON text ({exc.reason} at byte "
                                f"{exc.start})") from None
    try:
        data = load_json(text)
    except ValueError as exc:
        raise InvalidSceneError(f"{path}: not valid JSON ({exc})") from None
    try:
        return Scene.from_dict(data, repair=repair)
    except InvalidSceneError as exc:
        raise InvalidSceneError(f"{path}: {exc}") from None


def _required(data: dict[str, Any], key: str, where: str) -> Any:
    if key not in data:
        raise InvalidSceneError(f"{where}{key}: missing")
    return data[key]


def _no_unknown(data: dict[str, Any], allowed: set[str], where: str) -> None:
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise InvalidSceneError(f"{where}{unknown[0]}: unknown key")


def _number(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidSceneError(f"{what}: expected a number, got {shown(value)}")
    try:
        x = float(value)  # (an integer beyond float64 overflows)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x):
        raise InvalidSceneError(f"{what}: expected a finite number, got {shown(value)}")
    return x


def _vector(value: Any, what: str) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise InvalidSceneError(f"{what}: expected [x, y], got {shown(value)}")
    return _number(value[0], f"{what}[0]"), _number(value[1], f"{what}[1]")


def _ring(value: Any, what: str) -> list[tuple[float, float]]:
    if not isinstance(value, (list, tuple)):
        raise InvalidSceneError(f"{what}: expected a list of [x, y] points")
    return [_vector(p, f"{what}[{i}]") for i, p in enumerate(value)]


def _angle(data: dict[str, Any], key: str, where: str) -> float:
    deg = f"{key}_deg"
    if key in data and deg in data:
        raise InvalidSceneError(f"{where}{deg}: give {key} or {deg}, not both")
    if deg in data:
        return math.radians(_number(data[deg], f"{where}{deg}"))
    if key in data:
        return _number(data[key], f"{where}{key}")
    return 0.0


def _body(data: Any, i: int, repair: bool, t_max: float) -> SceneBody:
    where = f"bodies[{i}]"
    if not isinstance(data, dict):
        raise InvalidSceneError(f"{where}: expected an object, got {type(data).__name__}")
    name = data.get("name", f"body{i}")
    if not isinstance(name, str) or not name:
        raise InvalidSceneError(f"{where}.name: expected a non-empty string")
    where += "."
    _no_unknown(data, _BODY_KEYS, where)
    vertices = _ring(_required(data, "vertices", where), f"{where}vertices")
    holes_raw = data.get("holes", [])
    if not isinstance(holes_raw, list):
        raise InvalidSceneError(f"{where}holes: expected a list of rings")
    holes = [_ring(h, f"{where}holes[{k}]") for k, h in enumerate(holes_raw)]
    try:
        shape = as_shape({"vertices": vertices, "holes": holes}, f"{where}vertices ({name!r})",
                         repair=repair)
    except InvalidShapeError as exc:
        hint = "" if repair else " (--repair / repair=True may fix it)"
        raise InvalidSceneError(f"{exc}{hint}") from None
    velocity = _vector(data.get("velocity", [0, 0]), f"{where}velocity")
    acceleration = _vector(data.get("acceleration", [0, 0]), f"{where}acceleration")
    turn = _angle(data, "angular_velocity", where)
    turn_rate = _angle(data, "angular_acceleration", where)
    try:
        motion = Motion(velocity, acceleration, turn, turn_rate)
    except ValueError as exc:  # a number beyond the range the kernels take
        raise InvalidSceneError(f"{where}{exc}") from None
    try:
        check_reach(shape, motion, t_max, f"{where[:-1]} ({name!r})")
    except ValueError as exc:  # its motion would overflow float64 within t_max
        raise InvalidSceneError(str(exc)) from None
    return SceneBody(name, shape, motion)
