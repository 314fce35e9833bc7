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
