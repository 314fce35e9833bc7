"""Exact rational oracles, independent of polycontact and of GEOS: the area common to
two polygons, the longest vertical and horizontal segments inside both, and whether a
polygon is valid, for float64 coordinates taken exactly.

:func:`overlap_area` cuts the plane into vertical slabs at every vertex and at every
crossing of an edge of one polygon with an edge of the other. Inside a slab no two
edges cross, so the length of a vertical line's part inside both polygons is linear in
x, and the slab's share of the common area is its width times that length at the
slab's middle. Every number is a :class:`fractions.Fraction`: the answer is exact, zero
exactly when the interiors do not overlap. Cost about (n + m) × (breakpoints) rational
operations: meant for the few cases that disagree with GEOS, not for bulk use.

:func:`is_valid` applies the OGC rules of a polygon's validity (as GEOS's ``is_valid``)
with exact orientations: every ring has three distinct points and no two of its edges
meet except consecutive ones at their shared vertex (no fold back either); rings of
different loops meet at most at points, never cross or overlap; every hole lies in the
outer loop and in no other hole; the interior is connected (no two loops touch twice,
and no chain of touches closes a cycle). O(n²): for small polygons.
"""

from __future__ import annotations

from fractions import Fraction
from itertools import combinations

Point = tuple[Fraction, Fraction]


def _rings(poly) -> list[list[Point]]:
    """The loops of a shapely Polygon as exact points, closing point dropped."""
    out = []
    for ring in [poly.exterior, *poly.interiors]:
        if ring.is_empty:
            continue
        pts = [(Fraction(x), Fraction(y)) for x, y in list(ring.coords)[:-1]]
        out.append(pts)
    return out


def _edges(rings: list[list[Point]]) -> list[tuple[Point, Point]]:
    return [(r[i], r[(i + 1) % len(r)]) for r in rings for i in range(len(r))]


def orient(a: Point, b: Point, c: Point) -> int:
    """Exact sign of (b − a) × (c − a)."""
    d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return (d > 0) - (d < 0)


def _crossing_x(p: Point, q: Point, r: Point, s: Point) -> Fraction | None:
    """x of the point where segments pq and rs cross properly, None if they do not."""
    if orient(p, q, r) * orient(p, q, s) >= 0 or orient(r, s, p) * orient(r, s, q) >= 0:
        return None
    d1 = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    d2 = (q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0])
    t = d1 / (d1 - d2)
    return r[0] + t * (s[0] - r[0])


def _section(edges: list[tuple[Point, Point]], x: Fraction) -> list[tuple[Fraction, Fraction]]:
    """The parts of the vertical line at ``x`` (through no vertex) inside the polygon."""
    ys = []
    for p, q in edges:
        if (p[0] < x) != (q[0] < x):
            ys.append(p[1] + (x - p[0]) * (q[1] - p[1]) / (q[0] - p[0]))
    ys.sort()
    return list(zip(ys[0::2], ys[1::2]))


def _common_length(u: list[tuple[Fraction, Fraction]], v: list[tuple[Fraction, Fraction]]) -> Fraction:
    total = Fraction(0)
    for a0, a1 in u:
        for b0, b1 in v:
            lo, hi = max(a0, b0), min(a1, b1)
            if hi > lo:
                total += hi - lo
    return total


def _slabs(ea: list[tuple[Point, Point]], eb: list[tuple[Point, Point]]):
    """The slabs ``(x0, x1)`` between consecutive breakpoints (every vertex's x and
    every crossing's) over the common x-range of the two edge lists."""
    xs = {p[0] for p, _ in ea} | {p[0] for p, _ in eb}
    for p, q in ea:
        for r, s in eb:
            if max(p[0], q[0]) < min(r[0], s[0]) or max(r[0], s[0]) < min(p[0], q[0]):
                continue
            if max(p[1], q[1]) < min(r[1], s[1]) or max(r[1], s[1]) < min(p[1], q[1]):
                continue
            x = _crossing_x(p, q, r, s)
            if x is not None:
                xs.add(x)
    cuts = sorted(xs)
    lo = max(min(p[0] for p, _ in ea), min(p[0] for p, _ in eb))
    hi = min(max(p[0] for p, _ in ea), max(p[0] for p, _ in eb))
    return [(x0, x1) for x0, x1 in zip(cuts, cuts[1:]) if x1 > lo and x0 < hi]


def _edge_lists(a, b, shift: Point, swap: bool):
    def move(p: Point, d: Point) -> Point:
        q = (p[0] + d[0], p[1] + d[1])
        return (q[1], q[0]) if swap else q

    zero = (Fraction(0), Fraction(0))
    ea = [(move(p, zero), move(q, zero)) for p, q in _edges(_rings(a))]
    eb = [(move(p, shift), move(q, shift)) for p, q in _edges(_rings(b))]
    return ea, eb


def overlap_area(a, b, shift: Point = (Fraction(0), Fraction(0))) -> Fraction:
    """The exact area of the intersection of shapely Polygons ``a`` and ``b``, ``b``
    translated by ``shift`` first (exactly)."""
    ea, eb = _edge_lists(a, b, shift, False)
    area = Fraction(0)
    for x0, x1 in _slabs(ea, eb):
        mid = (x0 + x1) / 2
        area += (x1 - x0) * _common_length(_section(ea, mid), _section(eb, mid))
    return area


def widest_section(a, b, swap: bool = False) -> Fraction:
    """The longest vertical segment (horizontal with ``swap``) inside both shapely
    Polygons ``a`` and ``b``, exactly: 0 when their interiors do not overlap. A disc
    of radius r inside both has a vertical and a horizontal section of 2r through its
    centre, so r is at most half the smaller of the two."""
    ea, eb = _edge_lists(a, b, (Fraction(0), Fraction(0)), swap)
    best = Fraction(0)
    for x0, x1 in _slabs(ea, eb):
        # linear inside the slab: its largest value is at an end, found from two
        # values inside
        u, v = x0 + (x1 - x0) / 3, x0 + 2 * (x1 - x0) / 3
        lu = _common_length(_section(ea, u), _section(eb, u))
        lv = _common_length(_section(ea, v), _section(eb, v))
        best = max(best, 2 * lu - lv, 2 * lv - lu)
    return best


def _on_segment(p: Point, a: Point, b: Point) -> bool:
    return (orient(a, b, p) == 0 and min(a[0], b[0]) <= p[0] <= max(a[0], b[0])
            and min(a[1], b[1]) <= p[1] <= max(a[1], b[1]))


def _meet(a: Point, b: Point, c: Point, d: Point) -> bool:
    """Closed segments ab and cd share a point."""
    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return True
    return (_on_segment(c, a, b) or _on_segment(d, a, b) or _on_segment(a, c, d)
            or _on_segment(b, c, d))


def _inside(p: Point, ring: list[Point]) -> int:
    """1 strictly inside the ring, 0 on it, -1 outside (crossing number, exact)."""
    n = len(ring)
    inside = False
    for i in range(n):
        a, b = ring[i], ring[(i + 1) % n]
        if _on_segment(p, a, b):
            return 0
        if (a[1] > p[1]) != (b[1] > p[1]):
            x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            if p[0] < x:
                inside = not inside
    return 1 if inside else -1


def _ring_valid(r: list[Point]) -> bool:
    n = len(r)
    if len(set(r)) < 3 or len(set(r)) != n:
        return False
    for i in range(n):
        p, q, s = r[i - 1], r[i], r[(i + 1) % n]
        if orient(p, q, s) == 0 and (p[0] - q[0]) * (s[0] - q[0]) + (p[1] - q[1]) * (s[1] - q[1]) > 0:
            return False  # the edges fold back
    for i, j in combinations(range(n), 2):
        if j == i + 1 or (i == 0 and j == n - 1):
            continue
        if _meet(r[i], r[(i + 1) % n], r[j], r[(j + 1) % n]):
            return False
    return True


def _sample_inside(ring: list[Point], hole: list[Point]) -> int:
    """Where ``hole`` lies against ``ring`` (rings that do not cross): 1 inside, -1
    outside, judged at a vertex off the ring or, if every vertex is on it, at the
    middle of an edge off it."""
    for p in hole:
        side = _inside(p, ring)
        if side:
            return side
    for i in range(len(hole)):
        a, b = hole[i], hole[(i + 1) % len(hole)]
        side = _inside(((a[0] + b[0]) / 2, (a[1] + b[1]) / 2), ring)
        if side:
            return side
    return 0


def is_valid(poly) -> bool:
    """OGC validity of a shapely Polygon, decided exactly (see the module docstring)."""
    rings = []
    for r in _rings(poly):
        kept = [p for i, p in enumerate(r) if p != r[i - 1]]  # consecutive repeats
        rings.append(kept)
    if not all(_ring_valid(r) for r in rings):
        return False
    touches: dict[tuple[int, int], set[Point]] = {}
    for (i, r), (j, s) in combinations(enumerate(rings), 2):
        for a, b in zip(r, r[1:] + r[:1]):
            for c, d in zip(s, s[1:] + s[:1]):
                o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
                if o1 * o2 < 0 and o3 * o4 < 0:
                    return False  # cross
                if o1 == o2 == 0 and _meet(a, b, c, d):
                    k = 0 if a[0] != b[0] else 1
                    if min(max(a[k], b[k]), max(c[k], d[k])) > max(min(a[k], b[k]), min(c[k], d[k])):
                        return False  # overlap
                for p, (e, f) in ((c, (a, b)), (d, (a, b)), (a, (c, d)), (b, (c, d))):
                    if _on_segment(p, e, f):
                        touches.setdefault((i, j), set()).add(p)
    for k in range(1, len(rings)):
        if _sample_inside(rings[0], rings[k]) != 1:
            return False
        for m in range(1, len(rings)):
            if m != k and _sample_inside(rings[m], rings[k]) == 1:
                return False
    # Connected interior: loops as nodes, a touch point as an edge; two touches
    # between the same loops, or a cycle, cut the interior.
    parent = list(range(len(rings)))

    def root(u: int) -> int:
        while parent[u] != u:
            u = parent[u]
        return u

    for (i, j), pts in touches.items():
        if len(pts) > 1:
            return False
        ri, rj = root(i), root(j)
        if ri == rj:
            return False
        parent[ri] = rj
    return True
