"""Time of impact of two moving bodies: the paper's sampled search and a continuous one.

Bodies **collide** when their interiors come to overlap (penetration); touching without
penetrating (sliding along each other, grazing a corner) is a **contact**, reported by
``first_contact`` while ``collides`` stays False. :func:`time_of_impact` reports the
first penetration located to within the time tolerance from above; the exact meaning,
the method and its contract are in the theory page of the documentation.

Examples
--------
>>> from polycontact import Motion, Shape
>>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
>>> hit = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)), Motion(), t_max=5)
>>> hit.collides, round(hit.time, 3)
(True, 2.0)
"""

from __future__ import annotations

import enum
import threading
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from ._checks import finite_number
from ._dispatch import entry_point
from .broad_phase import (base_reach, check_motion, check_reach, check_t_max, intervals_array,
                          reach_excess)
from .motion import Motion
from .relation import Feature, Relation, State, classify
from .shape import Shape, ShapeLike, as_shape
from .limits import (BROAD_PHASE_INFLATION, CONTACT_RESOLUTION, MAX_ITERATIONS,
                     RELATIVE_TOLERANCE, SAMPLES, TIME_TOLERANCE)
from .tolerances import ROUNDING_FACTOR, check_range

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["Impact", "ImpactStatus", "time_of_impact", "CONTACT_RESOLUTION", "MAX_ITERATIONS"]

_METHODS = ("exact", "sampled")


class ImpactStatus(str, enum.Enum):
    """How a time-of-impact search ended.

    Examples
    --------
    >>> ImpactStatus("hit") is ImpactStatus.HIT, ImpactStatus.NO_HIT.value
    (True, 'no-hit')
    """

    #: The bodies penetrate: ``time`` is the first instant (to the tolerance).
    HIT = "hit"
    #: No penetration in [0, t_max] (they may touch: see ``first_contact``).
    NO_HIT = "no-hit"
    #: Interiors already overlap at t = 0; no impact time is reported.
    PENETRATING_AT_START = "penetrating-at-start"
    #: The exact method used its iteration budget before a verdict (a long slide);
    #: ``searched_to`` says how far it got.
    OUT_OF_ITERATIONS = "out-of-iterations"


_STATUS = {
    0: ImpactStatus.NO_HIT,
    1: ImpactStatus.HIT,
    2: ImpactStatus.PENETRATING_AT_START,
    3: ImpactStatus.OUT_OF_ITERATIONS,
}


@dataclass(frozen=True)
class Impact:
    """Result of :func:`time_of_impact`.

    ``features``, ``point`` and ``normal`` classify the bodies at the moment of impact;
    they are computed on first access (a query that only needs the time does not pay
    for them) and cached. Likewise, of a result of :func:`time_of_impact` only
    ``collides``, ``time`` and ``status`` are set when it is returned; the other fields
    are filled in together when one of them is first read (the same values).

    Attributes
    ----------
    collides : bool
        True when the interiors come to overlap within (0, t_max].
    time : float or None
        First penetration time (the bodies penetrate at ``time``), or None.
    first_contact : float or None
        First time found at which the bodies touch (boundary distance within the
        contact resolution), or None. For a collision it is at most ``time_bracket[0]``;
        when no touch was found before the bracket it is the bracket's start, up to
        ``time_tolerance`` before the bodies actually touch.
    state : State or None
        The relation at the reported instant: ``time`` for a hit, t = 0 when
        penetrating at the start, ``first_contact`` for a contact without collision;
        None when nothing happened.
    status : ImpactStatus
        How the search ended; OUT_OF_ITERATIONS means no verdict.
    method : str
        "exact" or "sampled".
    broad_phase : tuple of (float, float)
        The broad-phase intervals searched.
    time_bracket : (float, float) or None
        ``(t_lo, time)``: no penetration at ``t_lo``, penetration at ``time``.
    iterations : int
        Number of placements classified.
    searched_to : float
        How far in time the search got (t_max when it finished).
    time_tolerance : float
        The time tolerance honoured: the one asked for, or what float64 resolves at
        ``time`` (``searched_to`` without a hit), 4 · 2**-52 · abs(t), when that is
        larger. ``time`` is within it after the first penetration.
    features : tuple of Feature
        At the touching configuration: which vertex of which body meets which edge of
        the other (body "a" or "b"; 0-based indices in the caller's numbering, the
        vertices as passed, see :class:`polycontact.Feature`).
    point : ndarray of shape (2,) or None
        Contact point at the moment of impact (or of first contact).
    normal : ndarray of shape (2,) or None
        Unit contact normal there, from A towards B.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> hit = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)), Motion(), t_max=5)
    >>> hit.collides, hit.status.value, round(hit.time, 3), hit.normal.tolist()
    (True, 'hit', 2.0, [1.0, 0.0])
    >>> [round(t, 3) for t in hit.broad_phase[0]], hit.time_bracket[0] < hit.time
    ([1.586, 4.414], True)
    """

    collides: bool
    time: float | None
    first_contact: float | None
    state: State | None
    status: ImpactStatus
    method: str
    broad_phase: tuple[tuple[float, float], ...] = field(repr=False)
    time_bracket: tuple[float, float] | None = field(repr=False)
    iterations: int = field(repr=False)
    searched_to: float = field(repr=False)
    time_tolerance: float = field(repr=False)
    _bodies: tuple[Any, ...] = field(repr=False, compare=False, default=())

    if not TYPE_CHECKING:  # (mypy keeps checking attribute names)

        def __getattr__(self, name: str) -> Any:
            # Of a result built by time_of_impact only ``collides``, ``time`` and
            # ``status`` are set at once; the other fields are filled in together on
            # the first access to one of them, from the kernel's answer (``_lazy``):
            # building them cost more than the query's Python. Only called for
            # attributes not found the normal way.
            lazy = self.__dict__.get("_lazy") if name in _LAZY else None
            if lazy is None:
                raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
            self.__dict__.update(_lazy_fields(self._bodies, *lazy))
            return self.__dict__[name]

    @cached_property
    def _details(self) -> tuple[tuple[Feature, ...], np.ndarray | None, np.ndarray | None]:
        if self.state is None:
            return (), None, None
        a, ma, b, mb, eps_rel = self._bodies
        if self.status is ImpactStatus.HIT:
            assert self.time_bracket is not None  # a hit always has its bracket
            t_lo, t_hi = self.time_bracket
            if self.method == "exact":
                t_lo, t_hi = _fine_bracket(a, ma, b, mb, t_lo, t_hi, eps_rel)
            rel_hi = classify(a.at(ma, t_hi), b.at(mb, t_hi),
                              tolerance=_eps_at(a, ma, b, mb, t_hi, eps_rel))
            rel = rel_hi
            if self.method == "exact":
                from ._kernels.impact import speed_bound

                reach = (t_hi - t_lo) * speed_bound(ma.array, a.bounding_radius, mb.array,
                                                    b.bounding_radius, t_lo, t_hi)
                rel_lo = _relation_at(a, ma, b, mb, t_lo, eps_rel, reach)
                rel = rel_lo if rel_lo.state is State.CONTACT else rel_hi
            # the normal opposes the smallest translation that ends the (tiny) overlap
            # at `time`: at a corner-on-corner or flush touch it is the push direction
            normal = rel_hi.normal if rel_hi.state is State.PENETRATING else rel.normal
            point = rel.point
            features = rel.features
        elif self.status is ImpactStatus.PENETRATING_AT_START:
            rel = classify(a.at(ma, 0.0), b.at(mb, 0.0),
                           tolerance=_eps_at(a, ma, b, mb, 0.0, eps_rel))
            features, point, normal = rel.features, rel.point, rel.normal
        else:
            assert self.first_contact is not None  # a state without a hit is a contact
            rel = _relation_at(a, ma, b, mb, self.first_contact, eps_rel)
            features, point, normal = rel.features, rel.point, rel.normal
        return (
            tuple(features),
            None if point is None else np.asarray(point, dtype=np.float64),
            None if normal is None else np.asarray(normal, dtype=np.float64),
        )

    @property
    def features(self) -> tuple[Feature, ...]:
        """Which vertex of which body meets which edge of the other (see class doc)."""
        return self._details[0]

    @property
    def point(self) -> np.ndarray | None:
        """Contact point at the moment of impact (or of first contact)."""
        return self._details[1]

    @property
    def normal(self) -> np.ndarray | None:
        """Unit contact normal at the moment of impact, from A towards B."""
        return self._details[2]

    def to_dict(self, names: tuple[str, str] = ("a", "b")) -> dict[str, Any]:
        """The impact as a JSON-ready dict: the object ``polycontact collide --json``
        prints.

        Parameters
        ----------
        names : (str, str), default ("a", "b")
            The names of A and B: ``pair``, and each feature's ``body`` and
            ``other_body``.

        Returns
        -------
        dict
            Every attribute of the class (``state`` and ``status`` as their values,
            ``point`` and ``normal`` as ``[x, y]`` or None), ``features`` (each as
            :meth:`Feature.to_dict` with the body names) and ``pair``.

        Examples
        --------
        >>> import json
        >>> from polycontact import Motion, Shape, time_of_impact
        >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> hit = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)), Motion(), t_max=5)
        >>> d = hit.to_dict(("red", "blue"))
        >>> d["status"], round(d["time"], 3), d["pair"], d["features"][0]["other_body"]
        ('hit', 2.0, ['red', 'blue'], 'blue')
        >>> json.loads(json.dumps(d)) == d
        True
        """
        own = {"a": tuple(names), "b": (names[1], names[0])}
        features = []
        for f in self.features:
            item = f.to_dict()
            item["body"], item["other_body"] = own[f.body]
            features.append(item)
        return {
            "collides": self.collides,
            "time": self.time,
            "first_contact": self.first_contact,
            "state": None if self.state is None else self.state.value,
            "features": features,
            "point": None if self.point is None else [float(v) for v in self.point],
            "normal": None if self.normal is None else [float(v) for v in self.normal],
            "method": self.method,
            "broad_phase": [list(iv) for iv in self.broad_phase],
            "status": self.status.value,
            "pair": list(names),
            "time_bracket": None if self.time_bracket is None else list(self.time_bracket),
            "time_tolerance": self.time_tolerance,
            "iterations": self.iterations,
            "searched_to": self.searched_to,
        }

    def plot(self, ax: Axes | None = None, *, names: tuple[str, str] = ("A", "B")) -> Axes:
        """Draw both bodies at t = 0 and at the event, their centroid paths and the
        contact.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Drawn into a new figure when omitted (see
            :func:`polycontact.plotting.plot_impact`).
        names : (str, str), default ("A", "B")
            The bodies' names in the legend.

        Returns
        -------
        matplotlib Axes

        Examples
        --------
        >>> from polycontact import Motion, Shape
        >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> hit = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)), Motion(),
        ...                      t_max=5)
        >>> ax = hit.plot(names=("red", "blue"))
        """
        from .plotting.impact import plot_impact

        a, ma, b, mb, _ = self._bodies
        return plot_impact(a, ma, b, mb, self, names=names, ax=ax)


def _fine_bracket(a: Shape, ma: Motion, b: Shape, mb: Motion, t_lo: float, t_hi: float,
                  eps_rel: float) -> tuple[float, float]:
    """The exact method's bracket of the first penetration narrowed to the probe length
    λ/S (λ the contact resolution, S the speed bound), so that the features are read
    where the bodies touch: the search brackets it only to ``time_tolerance``. The
    same search, on [t_lo, t_hi] (no penetration at t_lo, one at t_hi) with a
    tolerance of 2λ/S; the coarse bracket if it stops without a hit."""
    from ._kernels import impact as ki

    la, lb = a.bounding_radius, b.bounding_radius
    lam = CONTACT_RESOLUTION * (la + lb)
    speed = ki.speed_bound(ma.array, la, mb.array, lb, t_lo, t_hi)
    if speed <= 0.0 or t_hi - t_lo <= lam / speed:
        return t_lo, t_hi
    (ra, ea, *_), (rb, eb, *_) = body_frame(a), body_frame(b)
    code, hi, lo, *_ = ki.exact_search_tables(
        (ra, a.packed[1], a.centroid, la), ea, ma.array, (rb, b.packed[1], b.centroid, lb), eb,
        mb.array, np.array([[t_lo, t_hi]]),
        (2.0 * lam / speed, eps_rel, ROUNDING_FACTOR, lam, MAX_ITERATIONS))
    return (lo, hi) if code == ki.HIT else (t_lo, t_hi)


def _eps_at(a: Shape, ma: Motion, b: Shape, mb: Motion, t: float, eps_rel: float) -> float:
    """The distance tolerance at time t, as the kernels compute it: the size term
    ``eps_rel`` or the float spacing of the coordinates at t, whichever is larger."""
    from ._kernels.impact import tolerance_at

    return float(tolerance_at(a.centroid, ma.array, a.bounding_radius, b.centroid, mb.array,
                              b.bounding_radius, t, eps_rel, ROUNDING_FACTOR))


def _relation_at(a: Shape, ma: Motion, b: Shape, mb: Motion, t: float, eps_rel: float,
                 reach: float = 0.0) -> Relation:
    """classify at time t, the tolerance (local to t) widened to the gap and to ``reach``.

    ``reach`` is how far the bodies can still move relative to each other before the
    penetration (speed bound × bracket length): every vertex that can meet an edge by
    then counts as touching.
    """
    from ._kernels.distance import boundary_distance

    pa = a.at(ma, t)
    pb = b.at(mb, t)
    gap = float(boundary_distance(*pa.packed, *pb.packed))
    eps = _eps_at(a, ma, b, mb, t, eps_rel)
    return classify(pa, pb, tolerance=max(eps, 1.01 * gap, 1.01 * reach))


def time_of_impact(
    a: ShapeLike,
    motion_a: Motion,
    b: ShapeLike,
    motion_b: Motion,
    *,
    t_max: float,
    method: str = "exact",
    time_tolerance: float = TIME_TOLERANCE,
    samples: int = SAMPLES,
    max_iterations: int = MAX_ITERATIONS,
) -> Impact:
    """First time at which two moving bodies penetrate, and where they meet.

    Both bodies move rigidly over [0, ``t_max``] (:class:`Motion`: velocity,
    acceleration, spin and angular acceleration about the area centroid). Only the
    broad-phase intervals (:func:`polycontact.broad_phase_intervals`, paper Eq. 5) are
    searched. ``method="exact"`` (default) is continuous and cannot miss a penetration
    deeper than the contact resolution; ``method="sampled"`` is the paper's §3 and can
    tunnel. Lengths and times are in any consistent units (those of the coordinates
    and of the motions).

    Parameters
    ----------
    a, b : ShapeLike
        The shapes at t = 0, holes allowed, in any form :func:`polycontact.shape.as_shape`
        takes (Shape, (N, 2) array, shapely Polygon, GeoJSON, vertices mapping, WKT, WKB).
    motion_a, motion_b : Motion
        Their motions about their area centroids.
    t_max : float
        End of the time window searched, in the motions' time unit: the search covers
        [0, ``t_max``]; a number >= 0.
    method : {"exact", "sampled"}, default "exact"
        "exact": conservative advancement, never tunnels (see Notes). "sampled": the
        paper's §3 steps 3–6, ``samples`` points per round.
    time_tolerance : float, default :data:`~polycontact.limits.TIME_TOLERANCE`
        Accuracy of ``time`` (the paper's threshold); any value > 0. Below what float64
        resolves at the time examined (4 · 2⁻⁵² · abs(t)) it is clamped there, and the
        result's ``time_tolerance`` says so.
    samples : int, default :data:`~polycontact.limits.SAMPLES`
        Points per round of the sampled method (>= 2, at most ``max_iterations``: a
        round may classify every one); ignored by "exact".
    max_iterations : int, default :data:`~polycontact.limits.MAX_ITERATIONS`
        Budget of the search: iterations of the exact method, classifications of the
        sampled one; when spent, the status is OUT_OF_ITERATIONS (no verdict), never a
        hang.

    Returns
    -------
    Impact
        ``collides``, ``time``, ``first_contact``, ``status``, and at the event the
        ``features``, ``point`` and ``normal``.

    Raises
    ------
    TypeError
        A body, a motion or a number of the wrong type (the message names it).
    ValueError
        An invalid body (:class:`~polycontact.InvalidShapeError`), a bad ``t_max``,
        ``time_tolerance``, ``method``, ``samples`` or ``max_iterations``, or
        coordinates, speeds or accelerations that would overflow float64 within
        [0, ``t_max``] (see :data:`~polycontact.limits.COORDINATE_LIMIT`).

    Examples
    --------
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> hit = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)), Motion(),
    ...                      t_max=5)
    >>> hit.collides, abs(hit.time - 2.0) < 1e-4, hit.status.value
    (True, True, 'hit')
    >>> slide = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((1.9, 1)), Motion(),
    ...                        t_max=1)                     # slides along from t = 0.9
    >>> slide.collides, round(slide.first_contact, 4), slide.state.value
    (False, 0.9, 'contact')
    >>> fine = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)), Motion(),
    ...                       t_max=5, time_tolerance=1e-300)   # below float64 at t = 2
    >>> fine.collides, fine.time_tolerance == 4 * 2.0**-52 * fine.time
    (True, True)

    Notes
    -----
    What ``time`` means, the proof that the exact method cannot skip a penetration, how
    it follows a sliding contact, its tolerances and its contract are in the theory
    page of the documentation (:doc:`/theory`, "Time of impact").
    """
    # Shapes and Motions (a simulation's loop) pass as they are; their arrays have the
    # types the compiled code was found for (see :mod:`polycontact._dispatch`)
    if (type(a) is Shape and type(b) is Shape and type(motion_a) is Motion
            and type(motion_b) is Motion):
        fixed, ma, mb = True, motion_a, motion_b
    else:
        fixed, a, b = False, as_shape(a, "a"), as_shape(b, "b")
        ma, mb = check_motion(motion_a, "motion_a"), check_motion(motion_b, "motion_b")
    if (type(t_max) is float and type(time_tolerance) is float and type(samples) is int
            and type(max_iterations) is int and 0.0 <= t_max < _INF
            and 0.0 < time_tolerance < _INF and 2 <= samples <= _INT64_MAX
            and 1 <= max_iterations <= _INT64_MAX and method in _METHODS
            and (samples <= max_iterations or method == "exact")):
        tol = time_tolerance  # the common case, checked in one expression
    else:
        t_max, tol = check_options(t_max, method, time_tolerance, samples, max_iterations)

    # coordinates (checked once per shape, with its body frame) and motions whose
    # products would overflow float64 are refused
    exact = method == "exact"
    fa, fb = a._frame, b._frame  # (the frames built, as body_frame returns them)
    if fa is None or exact and fa[1] is None:
        fa = body_frame(a, tables=exact, what="a")
    if fb is None or exact and fb[1] is None:
        fb = body_frame(b, tables=exact, what="b")
    ra, ea, base_a, pa = fa
    rb, eb, base_b, pb = fb
    la, lb = a._radius, b._radius
    if not (t_max <= _SAFE_SCALE and base_a <= _SAFE_SCALE and base_b <= _SAFE_SCALE
            and ma._largest <= _SAFE_SCALE and mb._largest <= _SAFE_SCALE) and (
                reach_excess(base_a, la, ma._norms, t_max) is not None
                or reach_excess(base_b, lb, mb._norms, t_max) is not None):
        check_reach(a, ma, t_max, "motion_a")  # raises, naming the motion
        check_reach(b, mb, t_max, "motion_b")
    # the size term of the distance tolerance; the kernels add the float spacing of the
    # coordinates at each time they examine (never a bound over all of [0, t_max])
    eps_rel = RELATIVE_TOLERANCE * (a._extent if a._extent > b._extent else b._extent)
    # this thread's scratch buffer (the kernels allocate nothing), grown when needed
    size = len(ra) + len(rb)
    try:
        cap, work = _LOCAL.work
    except AttributeError:
        cap, work = _grow_work(0)
    if size > cap:
        cap, work = _grow_work(size)
    args: tuple[Any, ...]
    if exact:
        args = (pa[0], pa[1], ma._array, pb[0], pb[1], mb._array, t_max, BROAD_PHASE_INFLATION,
                tol, eps_rel, ROUNDING_FACTOR, CONTACT_RESOLUTION * (la + lb), int(max_iterations),
                work)
    else:  # (the query's record, see _kernels.impact.exact_query: the exact method's at 0)
        args = ((ra, a._starts, a._centroid, la), ma._array, (rb, b._starts, b._centroid, lb),
                mb._array, (t_max, BROAD_PHASE_INFLATION, tol, eps_rel, ROUNDING_FACTOR, 0.0,
                            int(max_iterations), int(samples)), work)
    # the compiled code called directly when every argument has the type it always has
    # (Shapes and Motions), else through the dispatcher
    run = _ENTRY.get(method) if fixed else None
    out = run(*args) if run is not None else _query(method, args, fixed)
    # (the broad phase's intervals, left in the scratch, are recomputed if asked for)
    return impact_from_kernel(a, ma, b, mb, method, out, t_max, eps_rel, tol, None)


_LOCAL = threading.local()


def _grow_work(size: int) -> tuple[int, np.ndarray]:
    """A new scratch buffer for this thread's queries on bodies of up to ``size``
    vertices in all (at least 64, doubling): ``(capacity, buffer)``, kept in
    :data:`_LOCAL`."""
    from ._kernels.impact import work_floats

    cap = max(64, 2 * size)
    _LOCAL.work = cap, np.empty(getattr(work_floats, "py_func", work_floats)(cap))
    return _LOCAL.work  # type: ignore[no-any-return]


#: The compiled entry points of the query kernels by method, once :func:`_query` has
#: found them (for Shapes and Motions).
_ENTRY: dict[str, Any] = {}


def _query(method: str, args: tuple[Any, ...], fixed: bool) -> tuple[Any, ...]:
    """Run the query kernel of ``method`` on ``args``. ``fixed``: the bodies are Shapes
    and the motions Motions, so every argument has the type it always has (read-only
    shape and motion arrays, the body-frame tables, Python floats and ints): the
    compiled code is found (see :mod:`polycontact._dispatch`) and kept in
    :data:`_ENTRY` for the next calls; otherwise the call goes through the dispatcher."""
    from ._kernels import impact as ki

    run = ki.exact_call if method == "exact" else ki.sampled_query
    if fixed:
        run = _ENTRY[method] = entry_point(run, args)
    out: tuple[Any, ...] = run(*args)
    return out


def check_options(t_max: float, method: str, time_tolerance: float, samples: int,
                  max_iterations: int) -> tuple[float, float]:
    """The options of :func:`time_of_impact` checked (an error naming each bad one):
    ``(t_max, time_tolerance)`` as floats."""
    t_max = check_t_max(t_max)
    tol = finite_number(time_tolerance, "time_tolerance", positive=True)
    if method not in _METHODS:
        raise ValueError(f"method: expected one of {', '.join(_METHODS)}, got {method!r}")
    for name, value, least in (("samples", samples, 2), ("max_iterations", max_iterations, 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise TypeError(f"{name}: expected an integer, got {type(value).__name__} "
                            f"{value!r}")
        if not least <= value <= _INT64_MAX:
            raise ValueError(f"{name}: expected an integer from {least} to 2**63 - 1, got "
                             f"{value!r}")
    if method == "sampled" and samples > max_iterations:
        # refused before the search: its first round alone may classify every sample
        raise ValueError(
            f"samples: a round of the sampled search classifies up to {samples} time "
            f"points, more than max_iterations = {max_iterations} (its budget of "
            f"classifications); ask for fewer samples or a larger max_iterations")
    return t_max, tol


_INF = float("inf")
#: The largest count the kernels take (an int64).
_INT64_MAX = 2**63 - 1
#: When the body's reach at rest (``body_frame``'s ``base``, which is at least its
#: bounding radius), its motion's norms (``Motion._largest``) and t_max are all at most
#: this, the reach check passes
#: without computing it: with every quantity K <= 1e15, the bounds of
#: :func:`polycontact.broad_phase.reach_excess` are at most K + K^2 + K^3 (coordinates),
#: 2 K + 2 K^2 + K^3 (speeds), K + K^2 + (K + K^2)^2 K (accelerations, about 1e75) and
#: K + K^2 (angular speed), far below ``COORDINATE_LIMIT`` (1e100).
_SAFE_SCALE = 1e15


def body_frame(shape: Shape, tables: bool = True, what: str = "shape") -> tuple[Any, ...]:
    """``(r, tables, base, packed)``: the shape's vertices relative to its centroid;
    when asked for, their ``_kernels.advance.edge_table`` (the exact method's circle
    tree; the sampled method does not need it); how far the body reaches from the
    origin at rest (:func:`polycontact.broad_phase.base_reach`, for the reach check;
    at least the bounding radius); with the tables, the body as
    ``_kernels.impact.pack_body`` packs it for the exact kernel (else None). Built on first use and kept with the shape (it is
    immutable; the arrays are read-only), so that repeated queries on one shape build
    them once. On first use the coordinates are also checked
    (:func:`polycontact.tolerances.check_range`, the error naming ``what``)."""
    frame = shape._frame
    if frame is not None and (frame[1] is not None or not tables):
        return frame
    r, tab, base, packed = frame if frame is not None else (None, None, 0.0, None)
    if r is None:
        xy = shape.packed[0]
        check_range(xy, what)
        base = base_reach(shape)
        r = xy - shape.centroid
        r.flags.writeable = False
    if tables and tab is None:
        from ._kernels.advance import edge_table
        from ._kernels.impact import pack_body

        tab = edge_table(r, shape.packed[1])
        packed = pack_body(r, shape.packed[1], np.asarray(shape.centroid, dtype=np.float64),
                           float(shape.bounding_radius), tab)
        for arr in (*tab, *packed):
            arr.flags.writeable = False
    shape._frame = frame = (r, tab, base, packed)
    return frame


def impact_from_kernel(a: Shape, ma: Motion, b: Shape, mb: Motion, method: str,
                       out: tuple[Any, ...], t_max: float, eps_rel: float, tol: float,
                       intervals: np.ndarray | None) -> Impact:
    """The :class:`Impact` of a query kernel's answer ``out`` = (number of intervals,
    status code, t_hi, t_lo, first contact, iterations, t_reached): Python floats and
    ints (Numba boxes float64 and int64 so); the broad phase's ``intervals`` (None:
    recomputed on first access)."""
    code = out[1]
    # Built as the frozen dataclass's __init__ would, at a fraction of its cost per
    # query: the fields other than these on first access (see ``Impact.__getattr__``
    # and :func:`_lazy_fields`). The tests check that every field is there.
    impact = _new(Impact)
    d = impact.__dict__
    d["collides"] = hit = code == _HIT
    d["time"] = out[2] if hit else None
    d["status"] = _STATUS[code]
    d["_bodies"] = (a, ma, b, mb, eps_rel)
    d["_lazy"] = (out, method, t_max, tol, intervals)
    return impact


def _lazy_fields(bodies: tuple[Any, ...], out: tuple[Any, ...], method: str, t_max: float,
                 tol: float, intervals: np.ndarray | None) -> dict[str, Any]:
    """The fields of an :class:`Impact` that :func:`impact_from_kernel` leaves to the first access:
    ``first_contact``, ``state``, ``method``, ``time_bracket``, ``iterations``,
    ``searched_to``, ``broad_phase`` (``intervals``, or the kernel's recomputed: the same
    operations) and ``time_tolerance``."""
    _, code, t_hi, t_lo, t_contact, iters, reached = out
    first_contact = t_contact if t_contact >= 0.0 else None
    state = time = bracket = None
    if code == _HIT:
        # the kernel found the interiors overlapping at t_hi
        time, bracket, state = t_hi, (t_lo, t_hi), _PENETRATING
    elif code == _AT_START:
        first_contact, state = 0.0, _PENETRATING
    elif first_contact is not None:
        state = _CONTACT
    if code == _NO_HIT:
        reached = t_max
    if intervals is None:
        a, ma, b, mb, _ = bodies
        intervals = intervals_array(a, ma, b, mb, t_max)
    return {
        "first_contact": first_contact, "state": state, "method": method,
        "time_bracket": bracket, "iterations": iters, "searched_to": reached,
        "broad_phase": tuple(map(tuple, intervals.tolist())),
        # (the kernel's formula, run in Python: the same float operations)
        "time_tolerance": float(_effective_time_tolerance()(
            tol, time if time is not None else reached)),
    }


_new = object.__new__


def _effective_time_tolerance() -> Any:
    """The kernels' ``effective_time_tolerance`` as a Python function (the one behind
    the compiled kernel, or the kernel itself without the JIT)."""
    from ._kernels.impact import effective_time_tolerance

    return getattr(effective_time_tolerance, "py_func", effective_time_tolerance)


_LAZY = frozenset(("first_contact", "state", "method", "time_bracket", "iterations",
                   "searched_to", "broad_phase", "time_tolerance"))
# the kernels' status codes (keys of _STATUS) and the states they imply, as plain names
# (an Enum member lookup costs more than the comparisons)
_NO_HIT, _HIT, _AT_START = 0, 1, 2
_PENETRATING, _CONTACT = State.PENETRATING, State.CONTACT
