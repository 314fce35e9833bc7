"""Rigid motion of a body with constant linear and angular acceleration.

A body moves rigidly about its area centroid ``c`` (paper §5(3)):

    c(t) = c0 + v t + a t² / 2,    θ(t) = ω t + α t² / 2,
    p(t) = c(t) + R(θ(t)) (p0 − c0)

for every point ``p0`` of the body at t = 0. Angles are radians, counter-clockwise
positive (the frame convention of :mod:`polycontact.shape`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._checks import finite_number, point
from .tolerances import COORDINATE_LIMIT

__all__ = ["Motion"]


def _pair(value: Any, what: str) -> tuple[float, float]:
    # (no range: the queries refuse a motion whose products would overflow, naming it)
    x, y = point(value, what, limit=None).tolist()
    return x, y


@dataclass(frozen=True, slots=True)
class Motion:
    """Constant-acceleration rigid motion about the body's area centroid.

    Every component is a real number (not a string, a boolean or a complex number) and
    finite, else ``TypeError`` or ``ValueError`` naming the parameter. A motion that
    would carry a body's coordinates, speeds or accelerations beyond ±1e100 within a
    query's window is refused by that query, naming the motion.

    Parameters
    ----------
    velocity : (float, float)
        Velocity of the centroid at t = 0.
    acceleration : (float, float)
        Constant acceleration of the centroid.
    angular_velocity : float
        Angular velocity at t = 0, radians per unit time, counter-clockwise positive.
    angular_acceleration : float
        Constant angular acceleration, radians per unit time squared.

    Examples
    --------
    >>> m = Motion(velocity=(1, 0), angular_velocity=math.pi / 2)
    >>> translation, angle = m.pose(2.0)
    >>> translation.tolist(), round(angle, 6)
    ([2.0, 0.0], 3.141593)
    """

    velocity: tuple[float, float] = (0.0, 0.0)
    acceleration: tuple[float, float] = (0.0, 0.0)
    angular_velocity: float = 0.0
    angular_acceleration: float = 0.0
    # derived in __post_init__: the kernel vector and its bytes, |v|, |a|, |ω|, |α| and
    # the largest
    _array: np.ndarray = field(init=False, repr=False, compare=False)
    _bytes: bytes = field(init=False, repr=False, compare=False)
    _norms: tuple[float, float, float, float] = field(init=False, repr=False, compare=False)
    _largest: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "velocity", _pair(self.velocity, "velocity"))
        object.__setattr__(self, "acceleration", _pair(self.acceleration, "acceleration"))
        object.__setattr__(
            self, "angular_velocity", finite_number(self.angular_velocity, "angular_velocity")
        )
        object.__setattr__(
            self,
            "angular_acceleration",
            finite_number(self.angular_acceleration, "angular_acceleration"),
        )
        # the kernel vector, built once: a time-of-impact query passes it as it is, and
        # a batch joins the bytes it views (read-only) with the other motions'
        data = np.array([*self.velocity, *self.acceleration, self.angular_velocity,
                         self.angular_acceleration], dtype=np.float64).tobytes()
        object.__setattr__(self, "_bytes", data)
        object.__setattr__(self, "_array", np.frombuffer(data, np.float64))
        # |v|, |a|, |ω|, |α|: what the reach check of every query reads
        object.__setattr__(self, "_norms", (
            math.hypot(*self.velocity), math.hypot(*self.acceleration),
            abs(self.angular_velocity), abs(self.angular_acceleration)))
        object.__setattr__(self, "_largest", max(self._norms))

    def pose(self, t: float) -> tuple[np.ndarray, float]:
        """Where the motion has taken a body at time ``t``.

        Parameters
        ----------
        t : float
            The time (finite).

        Returns
        -------
        translation : ndarray of shape (2,)
            The centroid's displacement, ``v t + a t² / 2``.
        angle : float
            The turn, ``ω t + α t² / 2`` radians. The placed body is the body at t = 0
            rotated by ``angle`` about its centroid, then translated by
            ``translation`` (what :meth:`polycontact.Shape.moved` does).

        Raises
        ------
        ValueError
            ``t`` is not finite, or the motion carries the body beyond ±1e100 by then.

        Examples
        --------
        >>> translation, angle = Motion(velocity=(1, 0), angular_velocity=0.5).pose(2.0)
        >>> translation.tolist(), angle
        ([2.0, 0.0], 1.0)
        """
        t = finite_number(t, "t")
        v = np.asarray(self.velocity)
        a = np.asarray(self.acceleration)
        translation = v * t + 0.5 * a * t * t
        angle = self.angular_velocity * t + 0.5 * self.angular_acceleration * t * t
        if not (np.abs(translation).max() <= COORDINATE_LIMIT and abs(angle) < math.inf):
            raise ValueError(f"t: at t = {t:g} the motion carries the body beyond "
                             f"±{COORDINATE_LIMIT:g}: products of coordinates would overflow "
                             "float64")
        return translation, float(angle)

    @property
    def array(self) -> np.ndarray:
        """The motion as the kernel vector ``[vx, vy, ax, ay, ω, α]`` (float64,
        read-only: built once with the motion, which is immutable)."""
        return self._array
