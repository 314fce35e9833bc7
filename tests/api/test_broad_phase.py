"""Broad phase (paper Eq. 5 with accelerations) against dense sampling of the centroids."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples

from polycontact import Motion, Shape, broad_phase_intervals

SQ = Shape([(-1, -1), (1, -1), (1, 1), (-1, 1)])        # radius sqrt(2)
R2 = 2 * math.sqrt(2)


def covered(intervals, t):
    return any(s - 1e-9 <= t <= e + 1e-9 for s, e in intervals)


def test_constant_velocity_gives_the_two_roots():
    out = broad_phase_intervals(SQ, Motion(velocity=(1, 0)), SQ.moved((10, 0)), Motion(),
                                t_max=20)
    assert len(out) == 1 and out[0] == pytest.approx((10 - R2, 10 + R2))


def test_two_windows_when_a_body_passes_turns_back_and_passes_again():
    # x(t) = 4t - t²/2: passes x = 3 going out (t ~ 0.8) and again coming back (t ~ 7.2)
    out = broad_phase_intervals(SQ, Motion(velocity=(4, 0), acceleration=(-1, 0)),
                                SQ.moved((3, 0)), Motion(), t_max=10)
    assert len(out) == 2
    (s1, e1), (s2, e2) = out
    x = lambda t: 4 * t - t * t / 2
    for t in (s1, e1, s2, e2):
        assert abs(abs(x(t) - 3) - R2) < 1e-9
    assert 0 <= s1 < e1 < s2 < e2 <= 10


def test_overlap_at_start_is_kept():
    out = broad_phase_intervals(SQ, Motion(velocity=(1, 0)), SQ.moved((1, 0)), Motion(),
                                t_max=20)
    assert out[0][0] == 0.0 and out[0][1] == pytest.approx(1 + R2)


def test_grazing_circles_give_a_tiny_interval_not_nothing():
    out = broad_phase_intervals(SQ, Motion(velocity=(1, 0)), SQ.moved((10, R2)), Motion(),
                                t_max=20)
    assert len(out) == 1 and out[0][0] <= 10 <= out[0][1] and out[0][1] - out[0][0] < 1e-4


def test_no_relative_motion():
    assert broad_phase_intervals(SQ, Motion(), SQ.moved((1, 0)), Motion(), t_max=5) == (
        (0.0, 5.0),)
    assert broad_phase_intervals(SQ, Motion(velocity=(1, 1)), SQ.moved((10, 0)),
                                 Motion(velocity=(1, 1)), t_max=5) == ()


def test_t_max_zero_and_bad_t_max():
    assert broad_phase_intervals(SQ, Motion(), SQ.moved((1, 0)), Motion(), t_max=0) == (
        (0.0, 0.0),)
    with pytest.raises(ValueError, match="t_max"):
        broad_phase_intervals(SQ, Motion(), SQ, Motion(), t_max=math.inf)


def test_paper_case_2_interval_matches_the_paper():
    import polycontact as pc

    scene = pc.load_scene("examples/paper-case-2.json", repair=True)
    a, b = scene.bodies
    (s, e), = broad_phase_intervals(a.shape, a.motion, b.shape, b.motion, t_max=20)
    assert (round(s, 2), round(e, 2)) == (1.5, 10.0)


finite = st.floats(-3, 3, allow_nan=False)


@examples(60)
@given(st.tuples(finite, finite), st.tuples(finite, finite), st.tuples(finite, finite),
       st.tuples(finite, finite), st.tuples(st.floats(-8, 8), st.floats(-8, 8)))
def test_intervals_match_dense_sampling(va, aa, vb, ab, offset):
    b = SQ.moved(offset)
    ma, mb = Motion(velocity=va, acceleration=aa), Motion(velocity=vb, acceleration=ab)
    out = broad_phase_intervals(SQ, ma, b, mb, t_max=4.0)
    for (s, e), (s2, _) in zip(out, out[1:]):
        assert s <= e < s2
    for t in np.linspace(0, 4, 801):
        d = np.hypot(*(SQ.centroid + ma.pose(t)[0] - b.centroid - mb.pose(t)[0]))
        if d < R2 - 1e-7:
            assert covered(out, t)
        elif d > R2 + 1e-7:
            assert not covered(out, t)


def test_intervals_stay_right_at_long_travel():
    # a unit square 1e9 away (0.3 off the line) closing at 1 unit/s: the expanded
    # quartic (|d0|² = 1e18 swallowing R² = 2) gave the single instant (1e9, 1e9)
    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    half = math.sqrt(2 - 0.09)               # radii sqrt(0.5) each: R = sqrt(2)
    for offset in (0.0, 1e9):
        out = broad_phase_intervals(sq.moved((offset, 0)), Motion(velocity=(1, 0)),
                                    sq.moved((offset + 1e9, 0.3)), Motion(), t_max=2e9)
        assert len(out) == 1
        (s, e), = out
        assert 1e9 - half - 1e-4 <= s <= 1e9 - half and 1e9 + half <= e <= 1e9 + half + 1e-4


def _exact_distance(d0, dv, acc, t):
    """|D(t)| in exact rational arithmetic (then rounded once)."""
    from fractions import Fraction as F

    t = F(t)
    d = [F(d0[k]) + F(dv[k]) * t + F(acc[k]) * t * t / 2 for k in range(2)]
    return math.sqrt(float(d[0] * d[0] + d[1] * d[1]))


@given(st.floats(-1e9, 1e9), st.floats(0.0, 1e9), st.floats(1e-6, 1e12),
       st.floats(-1.5, 1.5), st.floats(-1e-3, 1e-3), st.sampled_from([0.0, 1.0, 1e3]))
@examples(60)
def test_intervals_right_far_away_at_long_travel(offset, travel, speed, lateral, acc_rel,
                                                 stretch):
    """Far from the origin, at long travel and any speed, with acceleration: every
    sampled instant at which the circles (radii sqrt(2) each, R2 in all) overlap, by exact
    arithmetic, is covered, and every interval end is where they touch (to the
    rounding of positions of that size)."""
    gap = R2 + travel
    t_hit = gap / speed
    t_max = t_hit * (1 + stretch) + 1.0 / speed
    acc = acc_rel * speed / t_max               # bends the path by <= 1e-3 of the travel
    a = SQ.moved((offset, offset))
    b = SQ.moved((offset + gap, offset + lateral * R2))
    ma = Motion(velocity=(speed, 0.0), acceleration=(acc, -acc))
    out = broad_phase_intervals(a, ma, b, Motion(), t_max=t_max)
    d0 = (a.centroid[0] - b.centroid[0], a.centroid[1] - b.centroid[1])
    dist = lambda t: _exact_distance(d0, (speed, 0.0), (acc, -acc), t)
    slack = 64 * 2.0**-52 * (abs(offset) + 2 * gap + speed * t_max) + 1e-12 * R2
    for t in np.linspace(0.0, t_max, 400):
        if dist(t) <= R2:
            assert any(s <= t <= e for s, e in out), t
    for s, e in out:
        for end in (s, e):
            if 0.0 < end < t_max:
                assert abs(dist(end) - R2) <= slack, (end, dist(end))


@examples(200)
@given(st.floats(-1e6, 1e6), st.sampled_from([1e-9, 1.0, 1e9]),
       st.lists(st.sampled_from([0.0, 1.0, 1e20, 1e40, 1e60, 1e99, 2e100]), min_size=4,
                max_size=4),
       st.sampled_from([0.0, 1e-3, 1.0, 1e30, 1e50, 1e200]))
def test_fast_reach_check_agrees_with_the_one_that_names_the_bound(offset, size, norms, t_max):
    # time_of_impact tests reach_excess with the base cached in the body frame and calls
    # check_reach (which raises, naming the bound) only when it fails: both must agree
    # with the bounds written out here, apart from the library
    from polycontact.broad_phase import base_reach, check_reach, reach_excess

    shape = Shape((np.array([(0, 0), (1, 0), (1, 1), (0, 1)]) + offset) * size)
    v, acc, w, alpha = norms
    motion = Motion(velocity=(v, 0.0), acceleration=(0.0, acc), angular_velocity=w,
                    angular_acceleration=alpha)
    cx, cy = shape.centroid
    rad, w_max = shape.bounding_radius, w + alpha * t_max
    bounds = (max(abs(cx), abs(cy)) + rad + v * t_max + acc * t_max * t_max / 2,
              v + acc * t_max + w_max * rad, acc + (alpha + w_max * w_max) * rad, w_max)
    within = all(x <= 1e100 for x in bounds)
    fast = reach_excess(base_reach(shape), shape.bounding_radius, motion._norms, t_max)
    assert (fast is None) == within
    if within:
        check_reach(shape, motion, t_max, "motion_a")
    else:
        with pytest.raises(ValueError, match="^motion_a: the body's "):
            check_reach(shape, motion, t_max, "motion_a")
