"""ESICUP nesting instances: pieces, allowed orientations, demand and strip height.

Reads the JSON form of the irregular strip-packing instances of the EURO Special
Interest Group on Cutting and Packing used by the jagua-rs project::

    {"name": ..., "strip_height": H,
     "items": [{"id": ..., "demand": n, "allowed_orientations": [degrees, ...],
                "shape": {"type": "simple_polygon", "data": [[x, y], ...]}}]}

A piece turned by ``a`` degrees is turned counter-clockwise about the origin of its
own coordinates (not about its centroid), as ESICUP defines it: :func:`turned`.

Examples
--------
>>> import json, tempfile, os
>>> doc = {"name": "two", "strip_height": 10, "items": [
...     {"id": 0, "demand": 2, "allowed_orientations": [0, 90],
...      "shape": {"type": "simple_polygon", "data": [[0, 0], [2, 0], [2, 1], [0, 1]]}}]}
>>> path = os.path.join(tempfile.mkdtemp(), "two.json")
>>> with open(path, "w") as f:
...     json.dump(doc, f)
>>> inst = read_esicup(path)
>>> len(inst.pieces), inst.orientations, inst.demand, inst.strip_height
(1, ((0.0, 90.0),), (2,), 10.0)
>>> turned(inst.pieces[0], 90).exterior.tolist()
[[0.0, 0.0], [0.0, 2.0], [-1.0, 2.0], [-1.0, 0.0]]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from os import PathLike
from typing import Any

import numpy as np

from ._checks import finite_number, shown
from ._json import load_json
from .errors import InvalidShapeError, PolycontactError
from .shape import Shape

__all__ = ["Instance", "InvalidInstanceError", "read_esicup", "turned", "turned_loops"]


class InvalidInstanceError(PolycontactError, ValueError):
    """A nesting instance file is malformed; the message names the file, item and key."""


@dataclass(frozen=True)
class Instance:
    """A nesting instance.

    Attributes
    ----------
    name : str
        The instance's name (the file's stem when the file has none).
    ids : tuple
        Each piece's ``id`` in the file.
    pieces : tuple of Shape
        The pieces in their own coordinates (orientation 0).
    orientations : tuple of tuple of float
        For each piece, the allowed angles in degrees (counter-clockwise, about the
        origin of the piece's coordinates).
    demand : tuple of int
        How many copies of each piece are to be placed.
    strip_height : float
        The height of the strip.

    Examples
    --------
    >>> from polycontact import datasets
    >>> inst = datasets.instance("jakobs1")
    >>> inst.name, len(inst.pieces), inst.orientations[0]
    ('jakobs1', 25, (0.0, 90.0, 180.0, 270.0))
    """

    name: str
    ids: tuple[Any, ...]
    pieces: tuple[Shape, ...]
    orientations: tuple[tuple[float, ...], ...]
    demand: tuple[int, ...]
    strip_height: float


def turned(shape: Shape, degrees: float) -> Shape:
    """``shape`` turned by ``degrees`` counter-clockwise about the origin (0, 0).

    Multiples of 90 degrees are exact (the sine and cosine are taken as the integers
    they are), so a table built at 0/90/180/270 keeps exact fits of the pieces.

    Examples
    --------
    >>> sq = Shape([(1, 0), (2, 0), (2, 1), (1, 1)])
    >>> turned(sq, 180).exterior.tolist()
    [[-1.0, 0.0], [-2.0, 0.0], [-2.0, -1.0], [-1.0, -1.0]]
    """
    loops = turned_loops(shape, degrees)
    if loops is None:
        return shape
    return Shape(loops[0], loops[1:])


def turned_loops(shape: Shape, degrees: float) -> list[np.ndarray] | None:
    """The loops of :func:`turned` (``shape.loops`` turned, not yet checked as a Shape),
    or None when the turn is none (a multiple of 360 degrees).

    >>> turned_loops(Shape([(1, 0), (2, 0), (2, 1), (1, 1)]), 90)[0].tolist()
    [[0.0, 1.0], [0.0, 2.0], [-1.0, 2.0], [-1.0, 1.0]]
    """
    deg = finite_number(degrees, "degrees", error=InvalidShapeError)
    quarter = deg / 90.0
    if quarter == round(quarter):
        c, s = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][int(round(quarter)) % 4]
    else:
        c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    if (c, s) == (1.0, 0.0):
        return None
    rot = np.array([[c, s], [-s, c]])  # row-vector form of R(degrees)
    return [loop @ rot for loop in shape.loops]


def read_esicup(path: str | PathLike[str]) -> Instance:
    """Read an ESICUP instance in the jagua-rs JSON form.

    Parameters
    ----------
    path : str or path-like
        The JSON file.

    Returns
    -------
    Instance

    Raises
    ------
    InvalidInstanceError
        When the file is not such an instance; the message names the item and key.
    InvalidShapeError
        When a piece is not a valid polygon (the message names the item).

    Examples
    --------
    See the module's example.
    """
    where = str(path)
    try:
        with open(path, "rb") as f:
            doc = load_json(f.read())
    except OSError as exc:
        raise InvalidInstanceError(f"{where}: cannot read: {exc.strerror or exc}") from None
    except ValueError as exc:  # (a UnicodeDecodeError too)
        raise InvalidInstanceError(f"{where}: not JSON: {exc}") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("items"), list):
        raise InvalidInstanceError(f"{where}: expected an object with a list 'items'")
    if not doc["items"]:
        raise InvalidInstanceError(f"{where}: 'items' is empty")
    height = _finite(doc.get("strip_height"))
    if height is None or height <= 0:
        raise InvalidInstanceError(f"{where}: 'strip_height': expected a positive number, "
                                   f"got {shown(doc.get('strip_height'))}")
    ids, pieces, orientations, demand = [], [], [], []
    for k, item in enumerate(doc["items"]):
        here = f"{where}: items[{k}]"
        if not isinstance(item, dict):
            raise InvalidInstanceError(f"{here}: expected an object")
        ids.append(item.get("id", k))
        n = item.get("demand", 1)
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise InvalidInstanceError(f"{here}: 'demand': expected an integer >= 0, got {n!r}")
        demand.append(n)
        angles = item.get("allowed_orientations", [0.0])
        if not isinstance(angles, list) or not angles or any(_finite(a) is None for a in angles):
            raise InvalidInstanceError(
                f"{here}: 'allowed_orientations': expected a non-empty list of finite "
                f"angles in degrees, got {shown(angles)}")
        for m, a in enumerate(angles):
            if any(abs(math.remainder(float(a) - float(b), 360.0)) <= 1e-9
                   for b in angles[:m]):
                raise InvalidInstanceError(
                    f"{here}: 'allowed_orientations': angle {a} is repeated (modulo 360) in "
                    f"{shown(angles)}")
        orientations.append(tuple(float(a) for a in angles))
        shape = item.get("shape")
        if not isinstance(shape, dict) or shape.get("type") != "simple_polygon":
            kind = shape.get("type") if isinstance(shape, dict) else shape
            raise InvalidInstanceError(
                f"{here}: 'shape': expected {{'type': 'simple_polygon', 'data': [[x, y], "
                f"...]}}, got type {kind!r}")
        try:
            pieces.append(Shape(shape.get("data")))
        except InvalidShapeError as exc:
            raise InvalidShapeError(f"{here}: {exc}") from None
        except (TypeError, ValueError) as exc:
            raise InvalidInstanceError(f"{here}: 'shape.data': {exc}") from None
    name = doc.get("name")
    if not isinstance(name, str):
        name = str(getattr(path, "stem", "")) or where.rsplit("/", 1)[-1].removesuffix(".json")
    return Instance(name, tuple(ids), tuple(pieces), tuple(orientations), tuple(demand),
                    height)


def _finite(x: Any) -> float | None:
    """``x`` as a float if it is a JSON number (not a boolean) that is a finite float64,
    else None."""
    if isinstance(x, bool) or not isinstance(x, int | float):
        return None
    try:
        value = float(x)
    except OverflowError:  # an integer beyond float64
        return None
    return value if math.isfinite(value) else None
