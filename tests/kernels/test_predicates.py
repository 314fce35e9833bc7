"""The exact predicates and the exact validity kernel against rational arithmetic.

Inputs are built to sit on, or a few float spacings off, the degenerate cases
(collinear points, a vertex on an edge) at every magnitude, where float arithmetic
alone decides wrongly. Also run as plain Python (NUMBA_DISABLE_JIT=1) by the CI script.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import shapely
from exact_overlap import is_valid, orient
from hypothesis import assume, example, given
from hypothesis import strategies as st
from profiles import examples

from polycontact._kernels import predicates as kp
from polycontact._kernels import validate as kv


def _exact(*xy: float) -> int:
    a, b, c = ((Fraction(xy[i]), Fraction(xy[i + 1])) for i in (0, 2, 4))
    return orient(a, b, c)


def _nudge(x: float, steps: int) -> float:
    """``x`` moved by ``steps`` float spacings."""
    for _ in range(abs(steps)):
        x = float(np.nextafter(x, np.inf if steps > 0 else -np.inf))
    return x


@st.composite
def near_collinear(draw):
    """Three points: a, b anywhere at one magnitude, c on the line ab (rounded) and
    nudged by a few float spacings, all translated by an offset."""
    scale = 10.0 ** draw(st.integers(-200, 200))
    offset = draw(st.sampled_from([0.0, 1.0, 1e9, -3e15, 7e40])) * scale
    coords = st.floats(-1.0, 1.0).filter(lambda x: x == 0.0 or abs(x) > 1e-30)
    ax, ay, bx, by = (draw(coords) * scale + offset for _ in range(4))
    t = draw(st.sampled_from([0.5, 0.25, 2.0, -1.0, 1.0 / 3.0]))
    cx = _nudge(ax + t * (bx - ax), draw(st.integers(-3, 3)))
    cy = _nudge(ay + t * (by - ay), draw(st.integers(-3, 3)))
    return ax, ay, bx, by, cx, cy


@given(near_collinear())
@examples(400)
@example((0.0, 0.0, 1.0, 1.0, 3.0, 3.0))
@example((0.1, 0.1, 0.3, 0.3, 0.7, 0.7))       # collinear in decimal, not in binary
@example((1e9, 1e9, 1e9 + 1.0, 1e9 + 0.5, 1e9 + 2.0, 1e9 + 1.0))
def test_orientation_is_exact(points):
    assert kp.orientation(*points) == _exact(*points)


@pytest.mark.parametrize("points", [
    (5e-324, 1.0, 1.0, 5e-324, 0.5, 0.5),      # 1 beside 5e-324, in x and in y
    (0.0, 0.0, 1.0, 0.0, 0.5, 5e-324),         # one float spacing off a line
    (0.0, 0.0, 1e-150, 1e-150, 3e-150, 3e-150),
    (1e100, 1e-300, -1e100, 3e-300, 0.0, 2e-300),
    (1e100, 1e-300, -1e100, 3e-300, 0.0, (1e-300 + 3e-300) / 2),
    (5e-324, 1e-323, 1e100, 5e-324, 1e-323, 1e-323),
])
def test_orientation_is_exact_where_products_underflow(points):
    assert kp.orientation(*points) == _exact(*points)


@st.composite
def extreme_points(draw):
    """Three points whose coordinates are 0, subnormal, tiny or up to 1e100, with a
    third point on or a float spacing off the line of the first two."""
    mags = st.sampled_from([0.0, 5e-324, 1e-320, 1e-310, 1e-300, 1e-200, 1.0, 1e100])
    ax, ay, bx, by = (draw(mags) * draw(st.sampled_from([1.0, -1.0, 3.0])) for _ in range(4))
    t = draw(st.sampled_from([0.5, 0.25, 2.0, -1.0]))
    cx = _nudge(ax + t * (bx - ax), draw(st.integers(-1, 1)))
    cy = _nudge(ay + t * (by - ay), draw(st.integers(-1, 1)))
    return ax, ay, bx, by, cx, cy


@given(extreme_points())
@examples(400)
@example((5e-324, 1.0, 1.0, 5e-324, 0.5, 0.5000000000000001))  # huge and subnormal products together
def test_orientation_is_exact_at_the_ends_of_the_range(points):
    assert kp.orientation(*points) == _exact(*points)


def _meet_exact(a, b, c, d) -> int:
    """0 apart, 1 touching, 2 crossing properly (rational arithmetic)."""
    a, b, c, d = ((Fraction(p[0]), Fraction(p[1])) for p in (a, b, c, d))
    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return 2

    def on(p, s, e, o):
        return o == 0 and min(s[0], e[0]) <= p[0] <= max(s[0], e[0]) and (
            min(s[1], e[1]) <= p[1] <= max(s[1], e[1]))

    return 1 if (on(c, a, b, o1) or on(d, a, b, o2) or on(a, c, d, o3) or on(b, c, d, o4)) else 0


@given(near_collinear(), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
@examples(400)
def test_segments_meet_is_exact(points, u, v):
    # segment cd through (or a few spacings off) segment ab, its other end anywhere
    ax, ay, bx, by, cx, cy = points
    span = abs(bx - ax) + abs(by - ay)
    dx, dy = cx + u * span, cy + v * span
    assume((dx, dy) != (cx, cy) and (ax, ay) != (bx, by))
    kind, _, _ = kp.segments_meet(ax, ay, bx, by, cx, cy, dx, dy)
    assert kind == _meet_exact((ax, ay), (bx, by), (cx, cy), (dx, dy))


@st.composite
def notched_rings(draw):
    """A ring with a vertex pushed to, onto or a few spacings across a non-adjacent
    edge (the notch of ``[(0, 0), (10, 0), (10, 10), (5, d), (0, 10)]`` and its like),
    scaled and moved anywhere."""
    scale = 10.0 ** draw(st.integers(-30, 30))
    offset = draw(st.sampled_from([0.0, 1e3, 1e9, 1e15]))
    angle = draw(st.sampled_from([0.0, 0.3, 1.0]))
    steps = draw(st.integers(-3, 3))
    depth = draw(st.sampled_from([0.0, 5e-15, 1e-13, 1e-300]))
    c, s = np.cos(angle), np.sin(angle)
    base = np.array([(0, 0), (10, 0), (10, 10), (5, depth), (0, 10)], dtype=float)
    ring = base @ np.array([[c, s], [-s, c]]) * scale + offset
    ring[3, 1] = _nudge(float(ring[3, 1]), steps)
    return ring


@given(notched_rings())
@examples(300)
@example(np.array([(0, 0), (10, 0), (10, 10), (5, 5e-15), (0, 10)], dtype=float))
@example(np.array([(0, 0), (10, 0), (10, 10), (5, 0), (0, 10)], dtype=float))
def test_first_defect_is_exact_validity(ring):
    xy = np.ascontiguousarray(ring)
    if len(np.unique(xy, axis=0)) < len(xy):
        return  # (a vertex rounded onto another: the cleaning before the kernel's work)
    code = kv.first_defect(xy, np.array([0, len(xy)]))[0]
    assert (code == kv.OK) == is_valid(shapely.Polygon(xy))
    if code == kv.OK:
        assert kv.loop_signs(xy, np.array([0, len(xy)]))[0] == np.sign(shapely.Polygon(xy).area)
