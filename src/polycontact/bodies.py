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

from collections.abc import Mapping
from typing import Any, Protocol, Union

import numpy.typing as npt

# (the coercion is Shape's own: ``Shape(...)`` takes every form too)
from .shape import BODY_FORMS, Shape, as_shape

__all__ = ["as_shape", "BODY_FORMS", "BodyLike", "GeoInterface"]


class GeoInterface(Protocol):
    """Anything with ``__geo_interface__`` (the Python geo interface)."""

    @property
    def __geo_interface__(self) -> Mapping[str, Any]: ...


#: The type of a body argument: every form :func:`as_shape` takes (WKT and JSON text are
#: ``str``, WKB ``bytes``; Shapely geometries have ``__geo_interface__``).
BodyLike = Union[Shape, GeoInterface, Mapping[str, Any], npt.ArrayLike]
