"""One way in: every form a body may take, turned into a :class:`~polycontact.Shape`.

Everywhere polycontact takes a body (the functions, :class:`Shape` itself,
``classify_many``, scenes, the command line) it accepts the same forms:

- a :class:`Shape` (used as it is);
- an array-like of shape (N, 2): the outer loop, closed or not, either orientation;
- a Shapely ``Polygon`` (or a ``MultiPolygon`` of exactly one part);
- anything with ``__geo_interface__`` (GeoPandas, other geometry libraries);
- a GeoJSON mapping: ``Polygon``, a ``MultiPolygon`` of one part, or a ``Feature``
  holding one;
- a body mapping ``{"vertices": [[x, y], ...], "holes": [...]}`` (an optional
  ``"name"`` is ignored), the scene files' form;
- WKT text (``"POLYGON ((0 0, 1 0, 0 1, 0 0))"``), JSON text of one of the mappings
  above or of a list of vertices (``"[[0, 0], [1, 0], [0, 1]]"``), WKB bytes or hex WKB
  text.

:class:`~polycontact.Shape` itself takes every one of these forms (``Shape(polygon)``);
:func:`as_shape` is the same coercion for functions, which names the argument in its
errors and returns a Shape unchanged.

A value of another type raises ``TypeError``; a value of an accepted type that is not a
valid polygon raises :class:`~polycontact.InvalidShapeError` (a ``ValueError``). Both
name the argument.

Examples
--------
>>> import shapely
>>> from polycontact.bodies import as_shape
>>> forms = [
...     [(0, 0), (1, 0), (1, 1), (0, 1)],
...     shapely.box(0, 0, 1, 1),
...     {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]},
...     {"vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]},
...     "POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))",
...     shapely.box(0, 0, 1, 1).wkb,
... ]
>>> [as_shape(f).area for f in forms]
[1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
>>> as_shape(3, "a")
Traceback (most recent call last):
...
TypeError: a: expected a body (Shape, (N, 2) array, shapely Polygon, GeoJSON or body mapping, WKT, WKB), got int
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any, Protocol, Union

import numpy as np
import numpy.typing as npt

from ._json import load_json
from .errors import InvalidShapeError
from .shape import Shape

__all__ = ["as_shape", "BODY_FORMS", "BodyLike", "GeoInterface"]


class GeoInterface(Protocol):
    """Anything with ``__geo_interface__`` (the Python geo interface)."""

    @property
    def __geo_interface__(self) -> Mapping[str, Any]: ...


#: The type of a body argument: every form :func:`as_shape` takes (WKT and JSON text are
#: ``str``, WKB ``bytes``; Shapely geometries have ``__geo_interface__``).
BodyLike = Union[Shape, GeoInterface, Mapping[str, Any], npt.ArrayLike]

#: The forms a body may take, as error messages list them.
BODY_FORMS = "Shape, (N, 2) array, shapely Polygon, GeoJSON or body mapping, WKT, WKB"

_BODY_KEYS = {"vertices", "holes", "name"}
_HEX = re.compile(r"(?:[0-9A-Fa-f]{2})+")


def as_shape(obj: Any, what: str = "shape", *, repair: bool = False) -> Shape:
    """``obj`` as a :class:`Shape`, whatever accepted form it takes (see the module).

    Parameters
    ----------
    obj : body
        One of the forms listed in the module docstring.
    what : str
        The argument's name, put at the start of every error message.
    repair : bool, default False
        Passed to :class:`Shape`: try ``shapely.make_valid`` on an invalid polygon.

    Returns
    -------
    Shape
        ``obj`` itself when it is already a Shape.

    Raises
    ------
    TypeError
        ``obj`` is of no accepted type.
    InvalidShapeError
        ``obj`` is of an accepted type but not a valid polygon.
    """
    if isinstance(obj, Shape):
        return obj
    try:
        return _coerce(obj, repair)
    except InvalidShapeError as exc:
        raise InvalidShapeError(f"{what}: {exc}") from None
    except TypeError as exc:
        raise TypeError(f"{what}: {exc}") from None


def _coerce(obj: Any, repair: bool) -> Shape:
    if isinstance(obj, (bytes, bytearray, memoryview)):
        return Shape.from_shapely(_from_wkb(bytes(obj)), repair=repair)
    if isinstance(obj, str):
        return _from_text(obj, repair)
    if hasattr(obj, "geom_type") and hasattr(obj, "wkb"):  # a shapely geometry
        return Shape.from_shapely(obj, repair=repair)
    if isinstance(obj, Mapping):
        return _from_mapping(obj, repair)
    geo = getattr(obj, "__geo_interface__", None)
    if isinstance(geo, Mapping):
        return _from_mapping(geo, repair)
    if isinstance(obj, (np.ndarray, list, tuple)):
        return Shape(obj, repair=repair)
    raise TypeError(f"expected a body ({BODY_FORMS}), got {type(obj).__name__}")


def _from_mapping(data: Mapping[str, Any], repair: bool) -> Shape:
    if "vertices" in data:
        unknown = sorted(set(data) - _BODY_KEYS)
        if unknown:
            raise InvalidShapeError(
                f"unknown key {unknown[0]!r} (a body mapping has 'vertices', 'holes', 'name')"
            )
        holes = data.get("holes", ())
        if holes is None or isinstance(holes, (str, bytes, Mapping)):
            raise InvalidShapeError("body mapping: 'holes' must be a list of rings")
        return Shape(data["vertices"], holes, repair=repair)
    if "type" in data:
        return Shape.from_geojson(dict(data), repair=repair)
    raise InvalidShapeError(
        "expected a GeoJSON mapping (with 'type') or a body mapping (with 'vertices'), "
        f"got keys {sorted(map(str, data))}"
    )


def _from_text(text: str, repair: bool) -> Shape:
    stripped = text.strip()
    if not stripped:
        raise InvalidShapeError("empty text: no body in it")
    if stripped.startswith(("{", "[")):
        try:
            data = load_json(text)
        except ValueError as exc:
            raise InvalidShapeError(f"not valid JSON ({exc})") from None
        if isinstance(data, list):  # the vertices alone: [[x, y], ...]
            return Shape(data, repair=repair)
        if not isinstance(data, Mapping):
            raise InvalidShapeError("JSON text: expected an object or a list of vertices")
        return _from_mapping(data, repair)
    if _HEX.fullmatch(stripped):  # hex WKB, as shapely's ``wkb_hex``
        return Shape.from_shapely(_from_wkb(bytes.fromhex(stripped)), repair=repair)
    return Shape.from_wkt(text, repair=repair)


def _from_wkb(data: bytes) -> Any:
    import shapely

    if not data:
        raise InvalidShapeError("empty WKB: no body in it")
    try:
        return shapely.from_wkb(data)
    except Exception as exc:  # noqa: BLE001 - GEOS raises its own error types
        raise InvalidShapeError(f"not valid WKB ({exc})") from None
