"""The entrance block E(A, B) of Shi's Contact Theory, built from its finite cover.

With a0 the reference point of A, the entrance block is the set of positions of a0 at
which the translated A touches or overlaps B: ``E(A, B) = B ⊕ (a0 − A)``. The theorem of
finite covers (paper Eq. 1) writes it as a union of small pieces, each made by one
element of A and one of B (every loop counts: holes bring their vertices and edges):

========== ======================================= =================================
kind       region (``p + S`` = S moved by p)        the reference point is in it when
========== ======================================= =================================
``A2-B0``  ``b_i + a0 − A``                        vertex b_i of B lies in A
``A0-B2``  ``B + a0 − a_j``                        vertex a_j of A lies in B
``A1e-B1f`` parallelogram ``f ⊕ (a0 − e)``         edge e of A meets edge f of B
``A1-B1f`` ``a0 − ∂A`` swept along edge f           some edge of A meets edge f of B
========== ======================================= =================================

``method="pairs"`` builds the m·n edge-pair parallelograms (paper §2.3);
``method="swept"`` builds one swept region per edge of B (paper §2.4). Both give the
same union. An edge pair that is parallel gives a parallelogram of zero width: it is kept
as a segment (a ``LineString``), and a swept region can have such segments too.

Which region the reference point is in decides the relation, but the verdict of
:meth:`EntranceBlock.classify` is that of :func:`polycontact.classify` on the translated
shapes (exact interior overlap), so it agrees with it everywhere, exact fits included.

Unions, intersections and differences are computed by GEOS snap-rounded to the
tolerance grid (``grid_size``), which is robust where floating-point overlay is not.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any, NamedTuple, cast

import numpy as np
import numpy.typing as npt

from . import limits
from ._checks import point as point_arg
from .errors import EntranceBlockTooLargeError
from .shape import Shape, ShapeLike, as_shape
from .tolerances import check_range, default_tolerance, snap_grid

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from shapely.geometry.base import BaseGeometry

    from .relation import Relation

__all__ = ["Component", "ComponentsAt", "Element", "EntranceBlock", "entrance_block"]

METHODS = ("swept", "pairs")

#: Component kinds and the family (paper Eq. 1 term) each belongs to.
FAMILIES = {"A2-B0": "A2-B0", "A0-B2": "A0-B2", "A1e-B1f": "A1-B1", "A1-B1f": "A1-B1"}


class Element(NamedTuple):
    """One vertex or edge of a body: ``body`` "a" or "b", ``kind`` "vertex" or "edge".

    ``loop`` and ``index`` are 0-based in the caller's numbering (the vertices as passed,
    whatever their orientation; see :meth:`polycontact.Shape.input_vertex`); edge k joins
    vertex k and vertex k + 1 of its loop. They are None for a vertex or edge that
    ``repair=True`` created.
    """

    body: str
    kind: str
    loop: int | None
    index: int | None  # type: ignore[assignment]  # shadows tuple.index, on purpose

    def __str__(self) -> str:
        where = ("" if self.loop == 0 else " of a loop made by the repair"
                 if self.loop is None else f" of hole {self.loop - 1}")
        return f"{self.body.upper()} {self.kind} {self.index}{where}"


@dataclass(frozen=True, eq=False)
class Component:
    """One piece of the finite cover of the entrance block.

    Attributes
    ----------
    kind : str
        ``"A2-B0"``, ``"A0-B2"``, ``"A1e-B1f"`` or ``"A1-B1f"`` (see the module table).
    features : tuple of Element
        The elements that make it: the vertex of B (``A2-B0``), the vertex of A
        (``A0-B2``), the edge of A and the edge of B (``A1e-B1f``), the edge of B
        (``A1-B1f``).
    geometry : shapely geometry
        The closed region of reference-point positions: a Polygon (with holes when the
        body has holes), a MultiPolygon, a LineString for a zero-width parallelogram, or
        a GeometryCollection when a swept region has zero-width parts.

    Examples
    --------
    >>> import polycontact as pc
    >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> c = pc.entrance_block(a, a.moved((3, 0))).components[0]
    >>> c.kind, c.family, c.label, c.geometry.area
    ('A2-B0', 'A2-B0', 'E(A(2), B(0))[B vertex 0]', 1.0)
    """

    kind: str
    features: tuple[Element, ...]
    geometry: BaseGeometry

    @property
    def family(self) -> str:
        """The term of paper Eq. 1 it belongs to: "A2-B0", "A0-B2" or "A1-B1"."""
        return FAMILIES[self.kind]

    @property
    def is_degenerate(self) -> bool:
        """True when the region has no area (a parallelogram of parallel edges)."""
        return bool(self.geometry.area == 0.0)

    @property
    def label(self) -> str:
        """The paper's notation, e.g. ``E(A(2), B(0))[B vertex 3]``."""
        inner = ", ".join(str(f) for f in self.features)
        left, right = {
            "A2-B0": ("A(2)", "B(0)"),
            "A0-B2": ("A(0)", "B(2)"),
            "A1e-B1f": ("A(1)", "B(1)"),
            "A1-B1f": ("A(1)", "B(1)"),
        }[self.kind]
        return f"E({left}, {right})[{inner}]"


class ComponentsAt(NamedTuple):
    """The components around a point: those holding it inside, those through it."""

    interior: tuple[Component, ...]
    boundary: tuple[Component, ...]


@dataclass(frozen=True, eq=False)
class EntranceBlock:
    """The entrance block of A to B as the union of its components.

    Build it with :func:`entrance_block`.

    Attributes
    ----------
    a, b : Shape
        The moving body (A) and the fixed one (B).
    reference : ndarray of shape (2,)
        The reference point a0 of A.
    method : str
        ``"swept"`` or ``"pairs"``.
    components : tuple of Component
        ``A2-B0`` components first (B's vertices loop by loop), then ``A0-B2`` (A's
        vertices), then the ``A1e-B1f`` pairs (A's edges outer, B's edges inner) or the
        ``A1-B1f`` swept regions (B's edges).
    tolerance : float
        Absolute tolerance: zero-width parallelograms and "on the boundary" in
        :meth:`components_at`.

    Examples
    --------
    >>> import polycontact as pc
    >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> eb = pc.entrance_block(a, a.moved((3, 0)))
    >>> eb
    <EntranceBlock method='swept', components: A2-B0 4, A0-B2 4, A1-B1 4>
    >>> eb.area, eb.classify(eb.reference).state.value
    (4.0, 'separate')
    """

    a: Shape
    b: Shape
    reference: np.ndarray
    method: str
    components: tuple[Component, ...]
    tolerance: float

    def of_family(self, family: str) -> tuple[Component, ...]:
        """The components of one term of paper Eq. 1.

        Parameters
        ----------
        family : {"A2-B0", "A0-B2", "A1-B1"}

        Returns
        -------
        tuple of Component

        Examples
        --------
        >>> import polycontact as pc
        >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> eb = pc.entrance_block(a, a.moved((3, 0)), method="pairs")
        >>> len(eb.of_family("A1-B1")), eb.of_family("A0-B2")[0].label
        (16, 'E(A(0), B(2))[A vertex 0]')
        """
        if family not in set(FAMILIES.values()):
            raise ValueError(f"family must be one of 'A2-B0', 'A0-B2', 'A1-B1', got {family!r}")
        return tuple(c for c in self.components if c.family == family)

    def to_shapely(self) -> BaseGeometry:
        """The entrance block as one shapely (Multi)Polygon: the union of the components.

        Zero-width components are left out: each lies in the union of the others (an
        edge sliding along a parallel edge has an end vertex on the other edge). Holes
        and pieces no wider than the tolerance, which rounding can leave where many
        components meet, are dropped. Computed once, on first use.

        Returns
        -------
        shapely geometry
            A Polygon or MultiPolygon.

        Examples
        --------
        >>> import polycontact as pc
        >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> region = pc.entrance_block(a, a.moved((3, 0))).to_shapely()
        >>> region.geom_type, region.area, region.bounds
        ('Polygon', 4.0, (2.5, -0.5, 4.5, 1.5))
        """
        return self._union

    @cached_property
    def _union(self) -> Any:
        import shapely

        # Components share edges up to rounding; floating-point GEOS overlay can fail on
        # such near-coincident edges ("Ring edge missing"), snap-rounding to the
        # tolerance grid cannot. The vertex components are joined first; the edge
        # components they cover (most of them) are then left out of the union.
        grid = snap_grid(self.tolerance)
        vertex = _union_on_grid(
            [c.geometry for c in self.components if c.family != "A1-B1"], grid
        )
        shapely.prepare(vertex)
        edge = np.array(
            [_polygonal(c.geometry) for c in self.components
             if c.family == "A1-B1" and not c.is_degenerate],
            dtype=object,
        )
        rest = edge[~shapely.covers(vertex, edge)] if len(edge) else edge
        union = _polygonal(_union_on_grid([vertex, *rest], grid))
        return _without_specks(union, self.tolerance)

    @property
    def area(self) -> float:
        """Area of the entrance block."""
        return float(self._union.area)

    @property
    def __geo_interface__(self) -> dict[str, Any]:
        """The entrance block as a GeoJSON-like (Multi)Polygon mapping (the union,
        :meth:`to_shapely`), for Shapely, GeoPandas and other geometry libraries."""
        return dict(self._union.__geo_interface__)

    def to_dict(self) -> dict[str, Any]:
        """The entrance block as a JSON-ready dict: the object
        ``polycontact entrance-block --json`` prints.

        Returns
        -------
        dict
            ``method``, ``reference`` (a0 as ``[x, y]``), ``components`` (the count of
            each family, "A2-B0", "A0-B2", "A1-B1"), ``zero_width_components``,
            ``area``, ``region`` (GeoJSON of :meth:`to_shapely`) and ``relation`` (the
            :meth:`Relation.to_dict` of A and B at a0).

        Examples
        --------
        >>> import polycontact as pc
        >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> d = pc.entrance_block(a, a.moved((3, 0))).to_dict()
        >>> d["components"], d["area"], d["relation"]["state"]
        ({'A2-B0': 4, 'A0-B2': 4, 'A1-B1': 4}, 4.0, 'separate')
        """
        import shapely

        return {
            "method": self.method,
            "reference": [float(v) for v in self.reference],
            "components": {f: len(self.of_family(f)) for f in ("A2-B0", "A0-B2", "A1-B1")},
            "zero_width_components": sum(c.is_degenerate for c in self.components),
            "area": self.area,
            "region": json.loads(shapely.to_geojson(self._union)),
            "relation": self.classify(self.reference).to_dict(),
        }

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the entrance block.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Without it, the four panels of
            :func:`polycontact.plotting.plot_entrance_block` (one per family, then the
            union) in a new figure; with it, only the union panel: B, A, E(A, B) with
            its outline and a0.

        Returns
        -------
        matplotlib Axes
            The Axes of E(A, B).

        Examples
        --------
        >>> import polycontact as pc
        >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> ax = pc.entrance_block(a, a.moved((3, 0))).plot()
        >>> len(ax.figure.axes)
        4
        """
        from .plotting.entrance_block import plot_entrance_block, plot_union

        if ax is None:
            return plot_entrance_block(self).axes[3]
        return plot_union(self, ax)

    def classify(self, point: npt.ArrayLike, *, tolerance: float | None = None) -> Relation:
        """Relation of A, moved so that its reference point is at ``point``, to B.

        Exactly :func:`polycontact.classify` of ``a.moved(point - reference)`` and ``b``:
        penetrating when ``point`` is inside the entrance block, contact on its boundary
        (an exact fit included), separate outside.

        Parameters
        ----------
        point : (x, y)
            Where A's reference point goes.
        tolerance : float, optional
            As for :func:`polycontact.classify`.

        Returns
        -------
        Relation

        Examples
        --------
        >>> import polycontact as pc
        >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> eb = pc.entrance_block(a, a.moved((3, 0)))
        >>> [eb.classify(p).state.value for p in [(3.0, 0.5), (2.5, 0.5), (2.4, 0.5)]]
        ['penetrating', 'contact', 'separate']
        """
        from .relation import classify

        return classify(self.a.moved(point_arg(point, "point") - self.reference), self.b, tolerance=tolerance)

    def components_at(self, point: npt.ArrayLike) -> ComponentsAt:
        """The components that hold ``point`` in their interior or on their boundary.

        This is the paper's reading of the cover (for teaching and for the features);
        it is not a verdict: a point on the boundaries of several components can be
        inside their union. Use :meth:`classify` for the relation.

        Parameters
        ----------
        point : (x, y)
            A position of A's reference point.

        Returns
        -------
        ComponentsAt
            ``interior``: the components holding it inside; ``boundary``: those within
            the tolerance of their outline.

        Examples
        --------
        >>> import polycontact as pc
        >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> eb = pc.entrance_block(a, a.moved((3, 0)), method="pairs")
        >>> for c in eb.components_at((3.0, 0.25)).interior:
        ...     print(c.label)
        E(A(2), B(0))[B vertex 0]
        E(A(0), B(2))[A vertex 2]
        E(A(1), B(1))[A edge 1, B edge 0]
        E(A(1), B(1))[A edge 2, B edge 3]
        >>> at = eb.components_at((2.5, 0.5))   # touching: on boundaries only
        >>> len(at.interior), len(at.boundary)
        (0, 11)
        """
        import shapely

        p = point_arg(point, "point")
        geoms = np.array([c.geometry for c in self.components], dtype=object)
        outlines = np.array([_outline(g) for g in geoms], dtype=object)
        near = shapely.dwithin(outlines, shapely.Point(p), self.tolerance)
        inside = shapely.contains_xy(geoms, p[0], p[1]) & ~near
        return ComponentsAt(
            interior=tuple(c for c, k in zip(self.components, inside) if k),
            boundary=tuple(c for c, k in zip(self.components, near) if k),
        )

    def __repr__(self) -> str:
        counts = ", ".join(
            f"{f} {len(self.of_family(f))}" for f in ("A2-B0", "A0-B2", "A1-B1")
        )
        return f"<EntranceBlock method={self.method!r}, components: {counts}>"


def entrance_block(
    a: ShapeLike, b: ShapeLike, reference: npt.ArrayLike | None = None, *,
    method: str = "swept"
) -> EntranceBlock:
    """The entrance block of A to B and its components (paper §2.3–2.4).

    Parameters
    ----------
    a, b : ShapeLike
        The moving body A and the fixed body B.
    reference : array_like of shape (2,), optional
        The reference point a0 of A; default A's area centroid (paper Eq. 3–4).
    method : {"swept", "pairs"}
        ``"pairs"``: one parallelogram per edge of A and edge of B (m·n components;
        more than :data:`~polycontact.limits.MAX_EDGE_PAIRS` are refused).
        ``"swept"``: one region per edge of B, the reflected boundary of A swept along
        it (n components); the paper's splice (§2.4, Fig. 6f) is used for every loop it
        is exact for (loops monotone across the edge), the union of the edge
        parallelograms for the others.

    Returns
    -------
    EntranceBlock

    Examples
    --------
    >>> import polycontact as pc
    >>> a = pc.Shape([(0, 0), (2, 0), (2, 1), (0, 1)])
    >>> eb = pc.entrance_block(a, a.moved((5, 0)))
    >>> eb
    <EntranceBlock method='swept', components: A2-B0 4, A0-B2 4, A1-B1 4>
    >>> eb.area                        # (2 + 2) × (1 + 1)
    8.0
    """
    a = as_shape(a, "a")
    b = as_shape(b, "b")
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(map(repr, METHODS))}, got {method!r}")
    if method == "pairs":
        pairs = len(a.packed[0]) * len(b.packed[0])
        if pairs > limits.MAX_EDGE_PAIRS:
            # refused before any is built: each is a geometry and an object
            raise EntranceBlockTooLargeError(
                f"entrance_block: method='pairs' would build {pairs} edge-pair "
                f"components ({len(a.packed[0])} x {len(b.packed[0])} edges), more than "
                f"limits.MAX_EDGE_PAIRS = {limits.MAX_EDGE_PAIRS}; use method='swept' "
                f"(one component per edge of b) or set "
                f"polycontact.limits.MAX_EDGE_PAIRS to allow more")
    a0 = a.centroid.copy() if reference is None else point_arg(reference, "reference")
    check_range(a0.reshape(1, 2), "reference")
    a0.flags.writeable = False
    eps = default_tolerance(a.packed[0], b.packed[0], a0.reshape(1, 2))
    comps = _vertex_of_b_in_a(a, b, a0) + _vertex_of_a_in_b(a, b, a0)
    if method == "pairs":
        comps += _edge_pairs(a, b, a0, eps)
    else:
        comps += _swept(a, b, a0, eps)
    return EntranceBlock(a, b, a0, method, comps, eps)


# -- components ------------------------------------------------------------------------
def _vertex_of_b_in_a(a: Shape, b: Shape, a0: np.ndarray) -> tuple[Component, ...]:
    """E(A(2), B(0)_i) = b_i + a0 − A, one per vertex of B (every loop)."""
    reflected = [a0 - loop for loop in a.loops]
    geoms = _translated_polygons(reflected, b.packed[0])
    return tuple(
        Component("A2-B0", (Element("b", "vertex", k, i),), g)
        for (k, i), g in zip(_indices(b, "vertex"), geoms)
    )


def _vertex_of_a_in_b(a: Shape, b: Shape, a0: np.ndarray) -> tuple[Component, ...]:
    """E(A(0)_j, B(2)) = B + a0 − a_j, one per vertex of A (every loop)."""
    geoms = _translated_polygons(list(b.loops), a0 - a.packed[0])
    return tuple(
        Component("A0-B2", (Element("a", "vertex", k, j),), g)
        for (k, j), g in zip(_indices(a, "vertex"), geoms)
    )


def _edge_pairs(a: Shape, b: Shape, a0: np.ndarray, eps: float) -> tuple[Component, ...]:
    """E(A(1)_e, B(1)_f) = f ⊕ (a0 − e) for every edge e of A and edge f of B."""
    e0, e1 = _edges(a)
    f0, f1 = _edges(b)
    # corners f0 − e0, f1 − e0, f1 − e1, f0 − e1 (plus a0), shape (m, n, 4, 2)
    corners = np.stack(
        [f0[None] - e0[:, None], f1[None] - e0[:, None], f1[None] - e1[:, None],
         f0[None] - e1[:, None]],
        axis=2,
    ) + a0
    geoms = _parallelograms(corners.reshape(-1, 4, 2), eps)
    ia, ib = _indices(a, "edge"), _indices(b, "edge")
    return tuple(
        Component(
            "A1e-B1f",
            (Element("a", "edge", *ia[p // len(ib)]), Element("b", "edge", *ib[p % len(ib)])),
            g,
        )
        for p, g in enumerate(geoms)
    )


def _swept(a: Shape, b: Shape, a0: np.ndarray, eps: float) -> tuple[Component, ...]:
    """E(A(1), B(1)_f): the reflected boundary a0 − ∂A swept along each edge f of B."""
    import shapely

    reflected = [a0 - loop for loop in a.loops]
    f0, f1 = _edges(b)
    comps = []
    for (k, i), start, end in zip(_indices(b, "edge"), f0, f1):
        areas, segments = zip(*(_swept_loop(loop + start, end - start, eps) for loop in reflected))
        area = areas[0] if len(areas) == 1 else _union_on_grid(areas, snap_grid(eps))
        lines = [g for group in segments for g in group]
        geom = shapely.GeometryCollection([area, *lines]) if lines else area
        comps.append(Component("A1-B1f", (Element("b", "edge", k, i),), geom))
    return tuple(comps)


def _swept_loop(loop: np.ndarray, v: np.ndarray, eps: float) -> tuple[Any, list[Any]]:
    """Region swept by the closed polyline ``loop`` translated by 0..``v``.

    Returns the part with area and the segments swept by the edges along v (zero width,
    kept apart: GEOS overlays on a grid take one dimension at a time).

    For a loop monotone across v (every line along v meets the region it encloses in
    one interval, e.g. a convex loop), the paper's splice (§2.4, Fig. 6f) gives the
    region swept by the filled loop; the curve sweeps all of it except the positions
    whose whole path stays inside, ``int P ∩ int(P + v)``, which is cut out. Other loops
    are swept edge by edge (the union of the edge parallelograms).
    """
    import shapely

    if _signed_area(loop) < 0.0:
        loop = loop[::-1]
    nxt = np.roll(loop, -1, axis=0)
    corners = np.stack([loop, nxt, nxt + v, loop + v], axis=1)
    flat = _flat(corners, eps)
    lines = list(_parallelograms(corners[flat], eps))
    spliced = _splice(loop, v)
    if spliced is None:
        return _union_on_grid(shapely.polygons(corners[~flat]), snap_grid(eps)), lines
    area = shapely.Polygon(spliced)
    cut = shapely.intersection(shapely.Polygon(loop), shapely.Polygon(loop + v),
                               grid_size=snap_grid(eps))
    if cut.area > 0.0:  # only the 2D part: where P and P + v merely touch, nothing is cut
        area = shapely.difference(area, _polygonal(cut), grid_size=snap_grid(eps))
    return area, lines


def _splice(loop: np.ndarray, v: np.ndarray) -> np.ndarray | None:
    """The paper's splice polygon for a CCW loop monotone across v, else None.

    The loop is cut at its farthest vertices on both sides of the translation line; the
    front chain (lo → hi, counter-clockwise) is translated by v and joined to the back
    chain (hi → lo) by the two translation lines.
    """
    h = _cross(v, loop)  # signed distance (times |v|) to the left of the line along v
    lo = int(np.argmin(h))
    ring = np.roll(loop, -lo, axis=0)
    hr = np.roll(h, -lo)
    hi = int(np.argmax(hr))
    if not (np.all(np.diff(hr[: hi + 1]) >= 0.0) and np.all(np.diff(np.r_[hr[hi:], hr[0]]) <= 0.0)):
        return None
    return np.concatenate([ring[: hi + 1] + v, ring[hi:], ring[:1]])


# -- helpers ---------------------------------------------------------------------------
def _indices(s: Shape, kind: str) -> list[tuple[int | None, int | None]]:
    """(loop, index) in the caller's numbering of every vertex or edge of ``s``, in
    packed (stored) order."""
    index = s.input_vertex if kind == "vertex" else s.input_edge
    return [(s.input_loop(k), index(k, i)) for k, loop in enumerate(s.loops)
            for i in range(len(loop))]


def _edges(s: Shape) -> tuple[np.ndarray, np.ndarray]:
    """Start and end points of every edge of every loop, packed order."""
    start = np.concatenate(s.loops)
    end = np.concatenate([np.roll(loop, -1, axis=0) for loop in s.loops])
    return start, end


def _cross(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    return cast("np.ndarray", u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0])


def _signed_area(ring: np.ndarray) -> float:
    return 0.5 * float(np.sum(_cross(ring, np.roll(ring, -1, axis=0))))


def _translated_polygons(loops: list[np.ndarray], offsets: np.ndarray) -> np.ndarray:
    """The polygon with rings ``loops`` (outer first) moved by each row of ``offsets``."""
    import shapely

    shells = shapely.linearrings(loops[0][None] + offsets[:, None])
    if len(loops) == 1:
        return cast("np.ndarray", shapely.polygons(shells))
    holes = np.stack(
        [shapely.linearrings(h[None] + offsets[:, None]) for h in loops[1:]], axis=1
    )
    return cast("np.ndarray", shapely.polygons(shells, holes=holes))


def _parallelograms(corners: np.ndarray, eps: float) -> np.ndarray:
    """Polygons of (K, 4, 2) corners; those narrower than eps become segments."""
    import shapely

    d1 = corners[:, 1] - corners[:, 0]
    d2 = corners[:, 3] - corners[:, 0]
    flat = _flat(corners, eps)
    out = np.empty(len(corners), dtype=object)
    out[~flat] = shapely.polygons(corners[~flat])
    if flat.any():
        c = corners[flat]
        axis = np.where(
            (np.hypot(*d2[flat].T) > np.hypot(*d1[flat].T))[:, None], d2[flat], d1[flat]
        )
        t = np.einsum("kij,kj->ki", c, axis)  # position of each corner along the segment
        rows = np.arange(len(c))
        ends = np.stack([c[rows, np.argmin(t, axis=1)], c[rows, np.argmax(t, axis=1)]], axis=1)
        out[flat] = shapely.linestrings(ends)
    return out


def _flat(corners: np.ndarray, eps: float) -> np.ndarray:
    """Which parallelograms of (K, 4, 2) corners are narrower than ``eps``."""
    d1 = corners[:, 1] - corners[:, 0]
    d2 = corners[:, 3] - corners[:, 0]
    longest = np.maximum(np.hypot(d1[:, 0], d1[:, 1]), np.hypot(d2[:, 0], d2[:, 1]))
    return cast("np.ndarray", np.abs(_cross(d1, d2)) <= eps * longest)


def _polygonal(geom: Any) -> Any:
    """The polygonal part of an overlay result: a Polygon when there is one piece."""
    import shapely

    flat = shapely.get_parts(shapely.get_parts(geom))  # collections may hold multi-parts
    parts = [g for g in flat if g.geom_type == "Polygon" and not g.is_empty]
    return parts[0] if len(parts) == 1 else shapely.MultiPolygon(parts)


def _without_specks(geom: Any, eps: float) -> Any:
    """``geom`` without the holes and pieces no wider than ``eps``.

    Where many components meet, rounding can leave a pinhole (or a sliver apart) a few
    grid steps wide that the exact union does not have. Every point of such a speck is
    within ``eps`` of the rest, where the classifier calls the bodies touching anyway.
    """
    import shapely

    def wide(ring_or_poly: Any) -> bool:
        poly = shapely.Polygon(ring_or_poly) if ring_or_poly.geom_type == "LinearRing" \
            else ring_or_poly
        return bool(shapely.maximum_inscribed_circle(poly, eps / 4).length > eps)

    pieces = [shapely.Polygon(p.exterior, [r for r in p.interiors if wide(r)])
              for p in shapely.get_parts(geom)]
    kept = [p for p in pieces if wide(p)] or [max(pieces, key=lambda p: p.area)]
    return kept[0] if len(kept) == 1 else shapely.MultiPolygon(kept)


def _outline(geom: Any) -> Any:
    """The topological boundary of a closed region: rings of areas, segments entire."""
    import shapely

    if geom.geom_type in ("Polygon", "MultiPolygon"):
        return geom.boundary
    if geom.geom_type in ("LineString", "MultiLineString"):
        return geom
    return shapely.union_all([_outline(g) for g in shapely.get_parts(geom)])


def _union_on_grid(geoms: Any, grid: float) -> Any:
    """Union of ``geoms`` snap-rounded to ``grid``. GEOS snaps the inputs first, which
    can make a valid input invalid (a hole's vertex within a grid step of its shell)
    and then refuse it ("side location conflict"; regression test
    test_entrance_block::test_union_of_components_a_hole_snaps_onto_its_shell); the
    inputs are then first made valid on that grid (``set_precision``), a change smaller
    than the grid step, which is below the tolerance."""
    import shapely

    try:
        return shapely.union_all(geoms, grid_size=grid)
    except shapely.errors.GEOSException:
        snapped = shapely.set_precision(np.asarray(geoms, dtype=object), grid)
        return shapely.union_all(snapped, grid_size=grid)
