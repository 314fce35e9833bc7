"""time_of_impact's contract against an oracle written apart from the library.

Contract (``time_of_impact`` docstring): whatever the speed, spin, acceleration, travel
length or time tolerance, a penetration of positive duration inside [0, t_max] that
goes deeper than the distance tolerance is found, and ``time`` is within the time
tolerance honoured (``Impact.time_tolerance``: the one asked for, or 4 · 2**-52 · |t|
when float64 cannot resolve finer) after the first such penetration.

The oracle places the bodies with its own rigid-motion code, and asks Shapely whether
the overlap of the placed polygons, eroded by a few distance tolerances, is non-empty
("deep"). It decides at most a bisection; its samples are provably fine enough:

- translation (flush, nearly flush and oblique approaches of convex bodies): the set of
  times at which two convex bodies translating along a line overlap, eroded or not, is
  an interval, which holds the instant of closest approach of the centroids when the
  path passes near enough; bisection between t = 0 and that instant gives the first
  deep time exactly, whatever the speed;
- spin: a bar spinning (with angular acceleration) about its centroid near the flat
  face of a large block sweeps its tip through the block once per half turn, for an
  angle of at least 2 acos((1 − δ + 0.01)/1) with the tip 0.01 deep; at the largest
  angular speed over the window that lasts longer than four samples.

The distance tolerance ``eps`` the oracle uses is its own copy of
``tolerance_for(extent, magnitude)`` at the time examined.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, example, given
from hypothesis import strategies as st
from profiles import examples

from polycontact import ImpactStatus, InvalidShapeError, Motion, Shape, time_of_impact

SQ = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
ULP = 2.0**-52


# -- the oracle ---------------------------------------------------------------------
class Body:
    """Vertices relative to the area centroid, and the centroid's rigid motion."""

    def __init__(self, xy, c0, v=(0.0, 0.0), w=0.0, al=0.0):
        self.r = np.asarray(xy, float) - np.mean(xy, axis=0)   # (convex, symmetric shapes)
        self.c0 = np.asarray(c0, float)
        self.v = np.asarray(v, float)
        self.w = float(w)
        self.al = float(al)

    def at(self, t):
        th = self.w * t + 0.5 * self.al * t * t
        c, s = math.cos(th), math.sin(th)
        x = self.r[:, 0] * c - self.r[:, 1] * s
        y = self.r[:, 0] * s + self.r[:, 1] * c
        return np.column_stack([self.c0[0] + self.v[0] * t + x, self.c0[1] + self.v[1] * t + y])

    def shape(self):
        return Shape(self.at(0.0))

    def motion(self):
        return Motion(velocity=tuple(self.v), angular_velocity=self.w,
                      angular_acceleration=self.al)


def oracle_eps(a: Body, b: Body, t: float) -> float:
    """The distance tolerance at t: max(1e-12 · extent, 64 ulps of the magnitude M of the
    coordinates' terms), M = max over bodies and axes of |c0| + |v| t + |a| t²/2 plus
    the body's size: a coordinate computed as c0 + v t is known to the float spacing of
    its largest term, not of its (maybe much smaller) value."""
    extent = max(np.ptp(a.at(0.0), axis=0).max(), np.ptp(b.at(0.0), axis=0).max())
    mag = max(np.max(np.abs(body.c0) + np.abs(body.v) * t) + np.abs(body.r).max()
              for body in (a, b))
    return max(1e-12 * extent, 64 * ULP * mag)


def deep(a: Body, b: Body, t: float, k: float = 3.0) -> bool:
    """The placed bodies overlap by more than k distance tolerances."""
    inter = shapely.Polygon(a.at(t)).intersection(shapely.Polygon(b.at(t)))
    return not inter.is_empty and not inter.buffer(-k * oracle_eps(a, b, t)).is_empty


def interiors_meet(a: Body, b: Body, t: float) -> bool:
    return bool(shapely.relate_pattern(shapely.Polygon(a.at(t)), shapely.Polygon(b.at(t)),
                                       "2********"))


def bisect_first(pred, lo, hi):
    """The first time in (lo, hi] where ``pred`` holds (false at lo, true at hi), to
    adjacent floats."""
    while True:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            return hi
        if pred(mid):
            hi = mid
        else:
            lo = mid


def check_contract(a: Body, b: Body, t_max: float, t_deep: float, tol: float):
    """The library finds the hit, no later than the contract allows, and it is real."""
    hit = time_of_impact(a.shape(), a.motion(), b.shape(), b.motion(), t_max=t_max,
                         time_tolerance=tol)
    assert hit.status is ImpactStatus.HIT, (hit, t_deep)
    honoured = max(tol, 4 * ULP * hit.time)
    assert hit.time_tolerance <= honoured * (1 + 1e-12)
    # no later than the first deep penetration plus the tolerance (and the oracle's own
    # bisection, to the float spacing of t)
    assert hit.time <= t_deep + hit.time_tolerance + 2 * ULP * t_deep, (hit, t_deep)
    # real: the interiors meet at `time`; none deeply before the bracket
    assert interiors_meet(a, b, hit.time)
    t_lo = hit.time_bracket[0]
    assert t_lo <= hit.time and not deep(a, b, t_lo)
    return hit


# -- translation: flush, nearly flush, oblique ----------------------------------------
@st.composite
def translations(draw):
    size = draw(st.sampled_from([1.0, 0.3, 7.0]))
    travel = draw(st.floats(1e-3, 1e9))
    speed = draw(st.floats(1e-6, 1e12))
    ox = draw(st.floats(-1e9, 1e9))
    oy = draw(st.floats(-1e9, 1e9))
    heading = draw(st.sampled_from([0.0, math.pi / 2, math.pi, 0.7, -2.1]))
    turn_b = draw(st.sampled_from([0.0, 0.0, 1e-9, 1e-6, 1e-3, 0.4]))   # 0: flush faces
    turn_a = draw(st.sampled_from([0.0, 0.0, 0.25]))
    lateral = draw(st.sampled_from([0.0, 0.3, -0.79, 0.5])) * size
    tol = draw(st.sampled_from([1e-300, 1e-16, 1e-12, 1e-4, 1e-2, 1.0]))
    stretch = draw(st.sampled_from([1.0, 1.0, 3.0, 1e3]))    # t_max beyond the hit
    return size, travel, speed, ox, oy, heading, turn_b, turn_a, lateral, tol, stretch


def _translation_case(size, travel, speed, ox, oy, heading, turn_b, turn_a, lateral):
    u = np.array([math.cos(heading), math.sin(heading)])
    n = np.array([-u[1], u[0]])
    sq = SQ * size
    rot = lambda xy, th: xy @ np.array([[math.cos(th), math.sin(th)],
                                        [-math.sin(th), math.cos(th)]])
    # A's faces along the heading (flush with B's when turn_b is 0)
    base = rot(sq - size / 2, heading)
    gap = travel + 2 * size            # centroid distance: apart by >= travel - ~0.8 size
    a = Body(rot(base, turn_a), (ox, oy), speed * u)
    b = Body(rot(base, turn_b), np.array([ox, oy]) + gap * u + lateral * n)
    return a, b, gap / speed


@given(translations())
@example((1.0, 2.0, 2e6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-4, 1.0))      # fast, flush
@example((1.0, 2.0, 1e12, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-4, 1.0))
@example((1.0, 1e9, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3, 1e-4, 1.0))      # long travel
@example((1.0, 2.0, 1.0, 1e9, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-4, 1.0))      # far from the origin
@example((1.0, 2.0, 1e-5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-12, 5.0))    # slow, tiny tolerance
@example((1.0, 2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-300, 1e3))
@examples(60)
def test_translation_matches_the_oracle(case):
    *geom, tol, stretch = case
    a, b, t_c = _translation_case(*geom)
    assume(not deep(a, b, 0.0) and deep(a, b, t_c))
    t_deep = bisect_first(lambda t: deep(a, b, t), 0.0, t_c)
    check_contract(a, b, t_c * stretch + 1.0 / a.v.dot(a.v) ** 0.5, t_deep, tol)


def test_tolerance_follows_the_terms_of_a_position_not_the_position():
    # Bodies that start near 4.6e8 and meet near the origin (t ~ 4.6e8): their
    # coordinates there are small, but c0 + v t is known only to the spacing of its
    # terms (6e-8), far above 64 ulps of the small coordinates (3e-9); the tolerance
    # followed the coordinates, so the bracket's lower end was already deep for the
    # oracle (CI seed, both found by test_translation_matches_the_oracle).
    for case in ((0.3, 463636790.0, 1.0, 463875800.0, 0.0, math.pi, 0.0, 0.25, 0.15),
                 (7.0, 466981704.0, 1e-06, 466916178.0, 0.0, math.pi, 0.4, 0.25, 3.5)):
        a, b, t_c = _translation_case(*case)
        t_deep = bisect_first(lambda t: deep(a, b, t), 0.0, t_c)
        stretch = 1.0 if case[2] == 1.0 else 1000.0
        check_contract(a, b, t_c * stretch + 1.0 / a.v.dot(a.v) ** 0.5, t_deep, 1e-300)


# -- spin with angular acceleration -----------------------------------------------------
@st.composite
def spins(draw):
    w0 = draw(st.floats(1.0, 1e3)) * draw(st.sampled_from([1.0, -1.0]))
    accel = draw(st.floats(-0.3, 0.3))        # |α| t_max <= 0.3 |ω0|
    depth = draw(st.floats(0.02, 0.3))        # how far the tip reaches into the block
    face = draw(st.floats(-math.pi, math.pi))
    ox = draw(st.floats(-1e9, 1e9))
    oy = draw(st.floats(-1e9, 1e9))
    tol = draw(st.sampled_from([1e-300, 1e-15, 1e-9, 1e-4, 1e-2, 1.0]))
    return w0, accel, depth, face, ox, oy, tol


@given(spins())
@example((0.5e0 * 2, 0.0, 0.02, 0.0, 1e9, 1e9, 1e-4))
@example((1e3, -0.3, 0.02, 1.0, -1e9, 3e8, 1e-300))
@examples(40)
def test_spin_matches_the_oracle(case):
    w0, accel, depth, face, ox, oy, tol = case
    u = np.array([math.cos(face), math.sin(face)])
    t_max = 3 * math.pi / abs(w0)
    al = accel * abs(w0) / t_max * math.copysign(1.0, w0)
    # a 2 x 0.2 bar, across the face at t = 0
    bar = np.array([(-1, -0.1), (1, -0.1), (1, 0.1), (-1, 0.1)]) @ np.array(
        [[-u[1], u[0]], [u[0], u[1]]]) * 1.0
    a = Body(bar, (ox, oy), w=w0, al=al)
    block = np.array([(0, -2), (4, -2), (4, 2), (0, 2)], float)
    rot = np.array([[u[0], u[1]], [-u[1], u[0]]])
    b = Body(block @ rot + np.array([ox, oy]) + (1 - depth) * u,
             np.array([ox, oy]) + (3 - depth) * u)
    assume(not deep(a, b, 0.0))
    w_max = abs(w0) * 1.3
    spacing = 2 * math.acos(min(1.0, (1 - depth + 0.01))) / w_max / 4
    prev = 0.0
    for t in np.arange(spacing, t_max, spacing):
        if deep(a, b, t):
            t_deep = bisect_first(lambda s: deep(a, b, s), prev, t)
            break
        prev = t
    else:
        pytest.fail("the bar never reached the block (the case is built so that it does)")
    check_contract(a, b, t_max, t_deep, tol)


# -- regression tests ------------------------------------------------------------------
@pytest.mark.parametrize("speed", [1.3e6, 1.6e6, 2e6, 5e6, 1e8, 1e12])
def test_fast_flush_square_does_not_tunnel(speed):
    # the squares overlap completely for 1 / speed; the classification tolerance had
    # grown with the travel (1e-12 x speed x t_max), let a touching vertex slip past
    # the corner of flush faces and the slide certificate step over the penetration
    hit = time_of_impact(SQ, Motion(velocity=(speed, 0)), SQ + [3, 0], Motion(), t_max=5)
    assert hit.collides and 2 / speed <= hit.time <= 2 / speed + hit.time_tolerance


@pytest.mark.parametrize("speed, vy, by, s_c", [
    (2e6, 0.5, 0.5, 2.6), (1e8, 0.5, 0.5, 2.6), (1e8, 0.5, 1.0, 2.6), (1e8, 0.1, 0.0, 3.0)])
def test_oblique_fast_approach_does_not_tunnel(speed, vy, by, s_c):
    # flush faces met on a slant: the old search said no hit for all of these
    a = Body(SQ, (0.5, 0.5), (speed, vy * speed))
    b = Body(SQ, (3.5, 0.5 + by))
    t_c = s_c / speed                 # the centroids are nearest: a deep overlap
    assert not deep(a, b, 0.0) and deep(a, b, t_c)
    t_deep = bisect_first(lambda t: deep(a, b, t), 0.0, t_c)
    check_contract(a, b, 5.0, t_deep, 1e-4)


def test_long_travel_to_a_far_body_hits():
    hit = time_of_impact(SQ, Motion(velocity=(1, 0)), SQ + [1e9, 0.3], Motion(), t_max=2e9)
    # eps at 1e9 is 64 ulps (1.4e-5): the first penetration beyond it is 1.4e-5 s late
    assert hit.collides and 999999999 <= hit.time <= 999999999 + 1e-4 + 2e-5
    (start, end), = hit.broad_phase
    assert start <= 999999999 and end >= 1e9 + 1


@pytest.mark.parametrize("offset", [1e8, 1e9])
def test_far_from_the_origin_hits_on_time(offset):
    hit = time_of_impact(SQ + [offset, 0], Motion(velocity=(1, 0)), SQ + [offset + 3, 0],
                         Motion(), t_max=5)
    eps = 64 * ULP * (offset + 5)
    assert hit.collides and 2.0 <= hit.time <= 2.0 + 1e-4 + eps


def test_answer_does_not_depend_on_t_max():
    a = Shape(SQ)
    b = a.moved((3, 0))
    for motion, first in ((Motion(velocity=(1, 0)), 2.0),
                          (Motion(velocity=(1, 0), angular_velocity=0.5), None)):
        times = []
        for t_max in (5, 1e8, 1e9, 1e13, 1e15):
            hit = time_of_impact(a, motion, b, Motion(), t_max=t_max)
            assert hit.collides, t_max
            times.append(hit.time)
        assert max(times) - min(times) <= 1e-4
        if first is not None:
            assert first <= min(times) and max(times) <= first + 1e-4 + 1e-12


@pytest.mark.parametrize("tol", [1e-16, 1e-300, 5e-324])
def test_time_tolerance_below_the_float_spacing_is_clamped(tol):
    a = Shape(SQ)
    hit = time_of_impact(a, Motion(velocity=(1, 0)), a.moved((3, 0)), Motion(), t_max=5,
                         time_tolerance=tol)
    assert hit.collides and hit.time_tolerance == pytest.approx(4 * ULP * hit.time)
    # the first penetration deeper than eps = 1e-12 is at 2 + 1e-12
    assert 2.0 <= hit.time <= 2.0 + 1e-12 + hit.time_tolerance
    slow = time_of_impact(a, Motion(velocity=(1e-5, 0)), a.moved((3, 0)), Motion(), t_max=1e6,
                          time_tolerance=1e-12)
    assert slow.collides and 2e5 <= slow.time <= 2e5 + 1e-12 / 1e-5 + slow.time_tolerance
    assert slow.time_tolerance == pytest.approx(4 * ULP * slow.time)


@pytest.mark.parametrize("side", [1e105, 1e154])
def test_huge_squares_are_refused_not_missed(side):
    # time_of_impact said "no hit" where there is one: coordinates whose products
    # overflow float64 are refused with an error that says so
    with np.errstate(all="ignore"), pytest.raises((InvalidShapeError, ValueError),
                                                   match="overflow"):
        time_of_impact(SQ * side, Motion(velocity=(side, 0)), SQ * side + [3 * side, 0],
                       Motion(), t_max=5)


@pytest.mark.parametrize("kwargs, what", [
    (dict(velocity=(1e60, 0)), "motion_a"),
    (dict(acceleration=(0, 1e30)), "motion_a"),
    (dict(angular_velocity=1e120), "motion_a"),
])
def test_motions_that_overflow_are_refused(kwargs, what):
    with pytest.raises(ValueError, match=f"{what}: .*overflow"):
        time_of_impact(SQ, Motion(**kwargs), SQ + [3, 0], Motion(), t_max=1e50)
