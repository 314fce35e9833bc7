"""A catalogue of canonical and degenerate placements of two bodies.

Every coordinate is exactly representable (small integers and halves), so Shapely
decides each case exactly and can serve as the oracle. Each :class:`Case` names the
expected state; tests may import :data:`CASES` (and :func:`shifted`) freely. The end of
the module holds hypothesis strategies for random star-shaped bodies (on the integer
grid, so that degenerate placements are exact, or not; with or without a hole) and the
Shapely oracle :func:`shapely_state`.

The shapes: unit squares, a U-shaped socket with a rectangular tab, a dovetail socket
and its piece (the overhangs hold the piece: it cannot move up, down or sideways), a
frame with a square hole, a square with a triangular hole whose tip touches the outer
boundary, crossing bars, triangles on edges and corners, and the hard cases of a
tolerance: a thin sliver whose tip dips 2**-20 .. 2**-33 into an edge, edges that
leave a touch point nearly collinear with the other body's edge (2**-20 .. 2**-40 rad,
into it or away from it). Their offsets are powers of two, so they stay exact too.

:func:`agrees_with_shapely` is the strict oracle comparison for inputs Shapely decides
on floats that are not exact: the same state, except that where Shapely's answer
differs from ours only within the tolerance, ours must be ``contact``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from hypothesis import assume
from hypothesis import strategies as st

from polycontact import Shape
from polycontact.errors import InvalidShapeError


def interlocking_combs(teeth: int) -> tuple[np.ndarray, np.ndarray]:
    """Two regular combs of ``4 teeth + 4`` vertices: one with its unit teeth down, one
    with its teeth up, each tooth exactly as wide as the other's gaps (the first fits
    into the second at every shift, sliding: ``2 teeth - 1`` slides in their no-fit
    polygon)."""
    w = 2 * teeth + 1
    up = [(0, 0), (w, 0), (w, 2), (w - 1, 2)]
    for i in range(teeth - 1, -1, -1):
        up += [(2 * i + 2, 1), (2 * i + 1, 1), (2 * i + 1, 2), (2 * i, 2)]
    down = [(0, 0), (w, 0), (w, 1)]
    for i in range(teeth - 1, -1, -1):
        down += [(2 * i + 2, 1), (2 * i + 2, 2), (2 * i + 1, 2), (2 * i + 1, 1)]
    down += [(0, 1)]
    return np.array(down, float) * [1.0, -1.0], np.array(up, float)


@dataclass(frozen=True)
class Case:
    """Two bodies and the state they are in (``"separate"``, ``"contact"``,
    ``"penetrating"``)."""

    name: str
    a: Shape
    b: Shape
    state: str


def _sq(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def _shape(outer, holes=()) -> Shape:
    return Shape(np.array(outer, dtype=float), [np.array(h, dtype=float) for h in holes])


UNIT = _shape(_sq(0, 0, 1, 1))
BIG = _shape(_sq(0, 0, 4, 4))
# U-shaped socket: a 4 x 2 block with a 2 x 1 notch cut from the middle of its top.
SOCKET = _shape([(0, 0), (4, 0), (4, 2), (3, 2), (3, 1), (1, 1), (1, 2), (0, 2)])
# The tab that fills the notch exactly and covers the top of the socket.
TAB = _shape([(1, 1), (3, 1), (3, 2), (4, 2), (4, 3), (0, 3), (0, 2), (1, 2)])
# Dovetail: the socket is wider at the bottom (1..5) than at the top (2..4).
DOVETAIL_SOCKET = _shape([(0, 0), (6, 0), (6, 3), (4, 3), (5, 1), (1, 1), (2, 3), (0, 3)])
DOVETAIL_PIECE = _shape([(1, 1), (5, 1), (4, 3), (4, 4), (2, 4), (2, 3)])
# A 4 x 4 frame with a 2 x 2 hole in the middle.
FRAME = _shape(_sq(0, 0, 4, 4), [_sq(1, 1, 3, 3)])
# A square whose triangular hole touches the outer boundary at (2, 0): valid (OGC).
PINCHED = _shape(_sq(0, 0, 4, 4), [[(2, 0), (3, 2), (1, 2)]])
HOLE_TRIANGLE = _shape([(2, 0), (3, 2), (1, 2)])
BAR_H = _shape(_sq(0, 1, 4, 2))
BAR_V = _shape(_sq(1, 0, 2, 4))
TRIANGLE_UP = _shape([(0, 0), (2, 0), (1, 1)])


def _sliver(d: float) -> Shape:
    """The issue's sliver: a kite over the unit square's top edge, its lower tip ``d``
    below that edge (into the square)."""
    return _shape([(0.5, 2), (0.2, 1), (0.5, 1 - d), (0.8, 1)])


def _tilted(slope: float) -> Shape:
    """A triangle touching the unit square's top edge at (0.5, 1), its lower edge
    leaving that point to the right with the given slope (negative: into the square)."""
    return _shape([(0.5, 1), (1.5, 1 + slope), (1.5, 2)])


def _moved(s: Shape, dx: float, dy: float) -> Shape:
    d = np.array([dx, dy])
    return _shape(s.exterior + d, [h + d for h in s.holes])


CASES: tuple[Case, ...] = (
    Case("identical squares", UNIT, UNIT, "penetrating"),
    Case("apart", UNIT, _moved(UNIT, 2, 0), "separate"),
    Case("apart diagonally, corners close", UNIT, _moved(UNIT, 1.5, 1.5), "separate"),
    Case("flush edges", UNIT, _moved(UNIT, 1, 0), "contact"),
    Case("flush, partly overlapping edges", BIG, _moved(UNIT, 4, 0.5), "contact"),
    Case("collinear edges, same side (overlap)", UNIT, _moved(UNIT, 0.5, 0), "penetrating"),
    Case("vertex on vertex", UNIT, _moved(UNIT, 1, 1), "contact"),
    Case("vertex on edge", UNIT, _shape([(0.5, 1), (1, 2), (0, 2)]), "contact"),
    Case("vertex into edge", UNIT, _shape([(0.5, 0.5), (1, 2), (0, 2)]), "penetrating"),
    Case("edge through vertex, inward", UNIT, _shape([(1, 0.5), (0.5, 2), (0, 2)]), "penetrating"),
    Case("triangle tip on corner", UNIT, _shape([(1, 1), (2, 3), (0, 3)]), "contact"),
    Case("triangle tip on corner, outward", UNIT, _shape([(1, 1), (3, 2), (2, 3)]), "contact"),
    Case("tab in its socket", SOCKET, TAB, "contact"),
    Case("tab above its socket", SOCKET, _moved(TAB, 0, 1), "contact"),
    Case("tab sunk into its socket", SOCKET, _moved(TAB, 0, -0.5), "penetrating"),
    Case("tab slid sideways", SOCKET, _moved(TAB, 0.5, 0), "penetrating"),
    Case("dovetail piece in its socket", DOVETAIL_SOCKET, DOVETAIL_PIECE, "contact"),
    Case("dovetail piece lifted", DOVETAIL_SOCKET, _moved(DOVETAIL_PIECE, 0, 0.5), "penetrating"),
    Case("square sliding in a slot of its width", SOCKET, _shape(_sq(1, 1, 3, 3)), "contact"),
    Case("square filling a hole exactly", FRAME, _shape(_sq(1, 1, 3, 3)), "contact"),
    Case("square in a hole, touching one side", FRAME, _shape(_sq(1, 1.5, 2, 2.5)), "contact"),
    Case("square in a hole, not touching", FRAME, _shape(_sq(1.5, 1.5, 2.5, 2.5)), "separate"),
    Case("square in a hole, poking out", FRAME, _shape(_sq(0.5, 1.5, 1.5, 2.5)), "penetrating"),
    Case("frame around a bigger square", FRAME, _shape(_sq(0.5, 0.5, 3.5, 3.5)), "penetrating"),
    Case("two frames, identical", FRAME, FRAME, "penetrating"),
    Case("square strictly inside a square", BIG, _shape(_sq(1, 1, 2, 2)), "penetrating"),
    Case("square inside, flush with one side", BIG, _shape(_sq(0, 1, 1, 2)), "penetrating"),
    Case("square inside, in a corner", BIG, _shape(_sq(0, 0, 1, 1)), "penetrating"),
    Case("triangle filling a pinched hole", PINCHED, HOLE_TRIANGLE, "contact"),
    Case("crossing bars (no vertex inside)", BAR_H, BAR_V, "penetrating"),
    Case("bar end flush on a bar side", BAR_H, _shape(_sq(1, 2, 2, 4)), "contact"),
    Case("triangle on an edge, base flush", UNIT, _moved(TRIANGLE_UP, -0.5, 1), "contact"),
    Case("triangles tip to tip", TRIANGLE_UP, _shape([(1, 1), (2, 2), (0, 2)]), "contact"),
    # A sliver's tip: penetrating as soon as the depth is above the tolerance (1e-12
    # here), whatever the thinness of the sliver; on the edge, contact.
    Case("sliver tip 2**-20 into an edge", UNIT, _sliver(2.0**-20), "penetrating"),
    Case("sliver tip 2**-33 into an edge", UNIT, _sliver(2.0**-33), "penetrating"),
    Case("sliver tip on an edge", UNIT, _sliver(0.0), "contact"),
    # Nearly collinear edges at a touch point: the lower edge of B leaves (0.5, 1) at a
    # tiny angle into A (a sliver of overlap 0.5 long, 2**-21 .. 2**-37 thick at A's
    # corner: penetrating) or away from it (contact only at the point).
    Case("edge 2**-20 rad into a flush edge", UNIT, _tilted(-(2.0**-20)), "penetrating"),
    Case("edge 2**-36 rad into a flush edge", UNIT, _tilted(-(2.0**-36)), "penetrating"),
    Case("edge 2**-20 rad away from a flush edge", UNIT, _tilted(2.0**-20), "contact"),
    Case("edge 2**-40 rad away from a flush edge", UNIT, _tilted(2.0**-40), "contact"),
)


def shifted(case: Case, dx: float, dy: float) -> Case:
    """The case with body B translated by (dx, dy); the state is left for the oracle."""
    return Case(f"{case.name} shifted by ({dx:g}, {dy:g})", case.a, _moved(case.b, dx, dy), "")


# -- random placements (hypothesis) and the Shapely oracle ---------------------------

STATES = ("separate", "contact", "penetrating")


def star_ring(draw, n_min: int, n_max: int, r_lo: float, r_hi: float, grid: bool) -> np.ndarray:
    """A star-shaped (generally concave) ring around the origin, angles evenly spread
    with jitter; rounded to integers when ``grid``."""
    n = draw(st.integers(n_min, n_max))
    jitter = np.array(draw(st.lists(st.floats(-0.4, 0.4), min_size=n, max_size=n)))
    angles = (np.arange(n) + jitter) * 2 * np.pi / n + draw(st.floats(0, 2 * np.pi))
    radii = np.array(draw(st.lists(st.floats(r_lo, r_hi), min_size=n, max_size=n)))
    ring = np.c_[np.cos(angles) * radii, np.sin(angles) * radii]
    return np.round(ring) if grid else ring


@st.composite
def shapes(draw, grid: bool | None = None, holes: bool | None = None, n_max: int = 10) -> Shape:
    """A valid Shape: random star polygon, on the integer grid or not, maybe with a hole."""
    grid = draw(st.booleans()) if grid is None else grid
    holes = draw(st.booleans()) if holes is None else holes
    if holes:
        outer = star_ring(draw, 7, max(n_max, 7), 4.0, 9.0, grid)
        inner = [star_ring(draw, 3, 6, 0.5, 2.0, grid)]
    else:
        outer = star_ring(draw, 3, n_max, 1.0, 9.0, grid)
        inner = []
    try:
        return Shape(outer, inner)
    except InvalidShapeError:
        assume(False)
        raise  # unreachable: assume(False) raises


def translated(s: Shape, d) -> Shape:
    """``s`` translated exactly by ``d`` (no rotation about the centroid)."""
    d = np.asarray(d, dtype=float)
    return Shape._trusted([loop + d for loop in s.loops])


@st.composite
def pairs(draw, grid: bool | None = None, holes: bool | None = None, n_max: int = 10):
    """Two shapes; B is placed at a random offset or with one vertex on one of A."""
    grid = draw(st.booleans()) if grid is None else grid
    a = draw(shapes(grid=grid, holes=holes, n_max=n_max))
    b = draw(shapes(grid=grid, holes=holes, n_max=n_max))
    if draw(st.booleans()):
        va = a.loops[0][draw(st.integers(0, len(a.loops[0]) - 1))]
        vb = b.loops[0][draw(st.integers(0, len(b.loops[0]) - 1))]
        d = va - vb
    elif grid:
        d = np.array(draw(st.lists(st.integers(-12, 12), min_size=2, max_size=2)), dtype=float)
    else:
        d = np.array(draw(st.lists(st.floats(-12, 12), min_size=2, max_size=2)))
    return a, translated(b, d), grid


def shapely_state(a: Shape, b: Shape) -> str:
    """The oracle: interiors meet in 2 dimensions, or boundaries meet, or neither."""
    pa, pb = a.to_shapely(), b.to_shapely()
    if pa.relate(pb)[0] == "2":
        return "penetrating"
    return "contact" if pa.intersects(pb) else "separate"


def boundary_gap(a: Shape, b: Shape) -> float:
    return float(shapely.distance(a.to_shapely().boundary, b.to_shapely().boundary))


# A ring of area 2e-4 at (82, 70): summing cross products of raw coordinates lost
# six digits of its area (a CI failure); every area sum is now taken relative to a vertex.
SMALL_FAR_RING = np.array([
    [82.01, 70.40625], [82.0096891242171, 70.40872403959254],
    [82.0087758256189, 70.41104425538605], [82.00731688868873, 70.41306638760024],
    [82.00540302305868, 70.41466470984808], [82.00431176516798, 70.415272675941],
    [82.00315322362395, 70.41573984619356], [82.00194547707989, 70.41605893057023],
    [82.00070737201668, 70.41622494986603], [82.00008296231624, 70.41624965585679],
    [81.99945822864973, 70.4162353134054], [81.9982175394435, 70.41608985946874],
    [81.99583853163453, 70.41534297426826], [81.99198856384453, 70.41223472144104],
    [81.990100075034, 70.4076612000806], [81.99346356379137, 70.39868197504693],
])


def feature_separation(a: Shape, b: Shape) -> float:
    """Smallest positive distance between a vertex and an edge of the two bodies (of
    either body, the same body included): below a few tolerances, float64 rounding of
    a scaled or offset copy may change the answer, so the scale tests skip there.
    Distances below 1e-14 of the bodies' extent are the rounding of this computation
    (a vertex on an edge, or the edge's own end) and count as zero."""
    loops = list(a.loops) + list(b.loops)
    pts = np.vstack(loops)
    floor = 1e-14 * float(np.ptp(pts, axis=0).max())
    p = pts[:, None, :]
    best = np.inf
    for loop in loops:
        u = loop
        w = np.roll(loop, -1, axis=0)
        d = (w - u)[None]
        den = np.maximum((d * d).sum(-1), 1e-300)
        t = np.clip(((p - u[None]) * d).sum(-1) / den, 0.0, 1.0)
        dist = np.hypot(*np.moveaxis(p - (u[None] + t[..., None] * d), -1, 0))
        pos = dist[dist > floor]
        if pos.size:
            best = min(best, float(pos.min()))
    return best


def agrees_with_shapely(a: Shape, b: Shape, ours: str, tolerance: float) -> bool:
    """``ours`` is Shapely's state, or ``contact`` where Shapely's answer differs only
    within the tolerance: a gap of at most ``2 * tolerance`` (Shapely: separate), an
    overlap thinner than ``4 * tolerance`` (Shapely: penetrating, and the overlap eroded
    by ``2 * tolerance`` is empty). Nothing else is accepted."""
    want = shapely_state(a, b)
    if ours == want:
        return True
    if ours != "contact":
        return False
    pa, pb = a.to_shapely(), b.to_shapely()
    if want == "separate":
        return float(shapely.distance(pa, pb)) <= 2.0 * tolerance
    overlap = shapely.intersection(pa, pb)
    return bool(shapely.buffer(overlap, -2.0 * tolerance).is_empty)


@st.composite
def touching_slivers(draw, holes: bool | None = None):
    """A random body A and a triangle B that touches an edge of A at a point p, B's
    first edge leaving p nearly collinear with A's edge: at an angle of 1e-12 .. 1e-6
    rad into A or away from it; B's opening angle at p is 1e-6 .. 1 rad (thin slivers
    included). Off the grid: Shapely decides on the rounded floats, so compare with
    :func:`agrees_with_shapely`."""
    a = draw(shapes(grid=False, holes=holes))
    ring = a.loops[0]
    k = draw(st.integers(0, len(ring) - 1))
    u, w = ring[k], ring[(k + 1) % len(ring)]
    length = float(np.hypot(*(w - u)))
    e = (w - u) / length
    out = np.array([e[1], -e[0]])              # A's interior is on the left of u -> w
    p = u + draw(st.floats(0.2, 0.8)) * (w - u)
    theta = 10.0 ** draw(st.floats(-12, -6)) * draw(st.sampled_from([1.0, -1.0]))
    beta = 10.0 ** draw(st.floats(-6, 0))
    span = draw(st.floats(0.1, 2.0)) * length
    backwards = draw(st.booleans())            # leave p towards u instead of w
    e1 = -e if backwards else e
    o1 = np.cos(theta) * e1 + np.sin(theta) * out   # theta > 0: away from A
    o2 = np.cos(theta + beta) * e1 + np.sin(theta + beta) * out
    b_ring = np.array([p, p + span * o1, p + span * o2])
    try:
        b = Shape(b_ring)
    except InvalidShapeError:
        assume(False)
        raise
    return a, b
