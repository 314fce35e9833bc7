"""Broad phase: when can two moving bodies touch at all (paper Eq. 5)?

Each body lies in its bounding circle: centre the area centroid, radius ``L`` the
largest centroid–vertex distance (:attr:`polycontact.Shape.bounding_radius`). The
circles move with the centroids, so the bodies can touch only while

    |c_A(t) − c_B(t)|² ≤ (L_A + L_B)²,

a polynomial inequality of degree 4 when the bodies accelerate (degree 2 without
acceleration, as in the paper). Unlike the paper's "two positive roots" wording, every
case is covered: circles already overlapping at t = 0, two separate windows (an
accelerated body that passes, turns back and passes again), a single grazing instant,
no relative motion at all.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._checks import finite_number
from .motion import Motion
from .shape import Shape, ShapeLike, as_shape
from .limits import BROAD_PHASE_INFLATION, COORDINATE_LIMIT
from .tolerances import check_range

__all__ = ["broad_phase_intervals", "BROAD_PHASE_INFLATION"]


def check_t_max(t_max: Any) -> float:
    """``t_max`` as a finite non-negative float, or a ValueError naming it."""
    return finite_number(t_max, "t_max", minimum=0.0)


def check_motion(motion: Any, what: str) -> Motion:
    if not isinstance(motion, Motion):
        raise TypeError(f"{what}: expected a polycontact.Motion, got {type(motion).__name__}")
    return motion


def check_reach(shape: Shape, motion: Motion, t_max: float, what: str) -> None:
    """Refuse a motion that carries the body's coordinates, or its points' speeds or
    accelerations, beyond :data:`polycontact.tolerances.COORDINATE_LIMIT` within
    [0, t_max]: the kernels square and multiply them, which would overflow float64.
    Raises ValueError naming ``what``.

    Examples
    --------
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> check_reach(sq, Motion(velocity=(1e60, 0)), 1e50, "motion_a")
    Traceback (most recent call last):
    ...
    ValueError: motion_a: the body's coordinates reach 1e+110 within t_max = 1e+50, beyond ±1e+100: products of coordinates would overflow float64
    """
    excess = reach_excess(base_reach(shape), shape.bounding_radius, motion._norms, t_max)
    if excess is None:
        return
    names = ("coordinates reach", "points' speeds reach", "points' accelerations reach",
             "angular speed reaches")
    for value, name in zip(excess, names):
        if not value <= COORDINATE_LIMIT:
            raise ValueError(
                f"{what}: the body's {name} {value:g} within t_max = {t_max:g}, beyond "
                f"±{COORDINATE_LIMIT:g}: products of coordinates would overflow float64"
            )


def base_reach(shape: Shape) -> float:
    """``max(abs(cx), abs(cy)) + radius``: how far from the origin the body reaches at
    rest (the first term of :func:`reach_excess`)."""
    cx, cy = shape.centroid.tolist()
    return float(max(abs(cx), abs(cy)) + shape.bounding_radius)


def reach_excess(base: float, radius: float, norms: tuple[float, float, float, float],
                 t_max: float) -> tuple[float, float, float, float] | None:
    """None when a body of reach ``base`` at rest (:func:`base_reach`) and bounding
    radius ``radius``, moving with ``norms`` = (abs(v), abs(a), abs(ω), abs(α))
    (``Motion._norms``), keeps its coordinates, point speeds, point accelerations and
    angular speed within :data:`~polycontact.tolerances.COORDINATE_LIMIT` over
    [0, ``t_max``]; else those four bounds (one of them beyond the limit, or nan). The
    test of :func:`check_reach`, for callers that keep the base (time_of_impact).

    >>> reach_excess(2.0, 1.0, (1.0, 0.0, 0.0, 0.0), 10.0) is None
    True
    >>> reach_excess(2.0, 1.0, (1e60, 0.0, 0.0, 0.0), 1e50)[0]
    1e+110
    """
    v, acc, w, alpha = norms
    w_max = w + alpha * t_max
    reach = base + v * t_max + 0.5 * acc * t_max * t_max
    speed = v + acc * t_max + w_max * radius
    accel = acc + (alpha + w_max * w_max) * radius
    if (reach <= COORDINATE_LIMIT and speed <= COORDINATE_LIMIT and accel <= COORDINATE_LIMIT
            and w_max <= COORDINATE_LIMIT):
        return None
    return reach, speed, accel, w_max


def intervals_array(a: Shape, ma: Motion, b: Shape, mb: Motion, t_max: float) -> np.ndarray:
    """The intervals as a (k, 2) float64 array (the form the kernels take)."""
    from ._kernels.broad_phase import overlap_intervals

    intervals: np.ndarray = overlap_intervals(
        np.asarray(a.centroid, dtype=np.float64), ma.array, a.bounding_radius,
        np.asarray(b.centroid, dtype=np.float64), mb.array, b.bounding_radius,
        t_max, BROAD_PHASE_INFLATION,
    )
    return intervals


def broad_phase_intervals(
    a: ShapeLike, motion_a: Motion, b: ShapeLike, motion_b: Motion, *, t_max: float
) -> tuple[tuple[float, float], ...]:
    """Closed time intervals within ``[0, t_max]`` when the bounding circles overlap.

    Parameters
    ----------
    a, b : ShapeLike
        The bodies at t = 0.
    motion_a, motion_b : Motion
        Their motions (about their area centroids).
    t_max : float
        End of the time window (>= 0).

    Returns
    -------
    tuple of (start, end) pairs
        Sorted, disjoint; empty when the circles never meet. ``start == end`` for a
        single grazing instant. Outside these intervals the bodies cannot touch.

    Examples
    --------
    >>> sq = Shape([(-1, -1), (1, -1), (1, 1), (-1, 1)])      # radius sqrt(2)
    >>> far = sq.moved((10, 0))
    >>> [(round(s, 4), round(e, 4)) for s, e in broad_phase_intervals(
    ...     sq, Motion(velocity=(1, 0)), far, Motion(), t_max=20)]
    [(7.1716, 12.8284)]
    """
    a = as_shape(a, "a")
    b = as_shape(b, "b")
    ma = check_motion(motion_a, "motion_a")
    mb = check_motion(motion_b, "motion_b")
    t_max = check_t_max(t_max)
    check_range(a.packed[0], "a")
    check_range(b.packed[0], "b")
    check_reach(a, ma, t_max, "motion_a")
    check_reach(b, mb, t_max, "motion_b")
    out = intervals_array(a, ma, b, mb, t_max)
    return tuple((float(s), float(e)) for s, e in out)
