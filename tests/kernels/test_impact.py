"""Impact and broad-phase kernels against plain NumPy / Shapely references.

Small inputs: this file also runs with NUMBA_DISABLE_JIT=1 (see .ci/run).
"""

import math
import warnings

import numpy as np
import shapely
from hypothesis import assume, example, given
from hypothesis import strategies as st
from profiles import examples

from polycontact import Motion, Shape
from polycontact._kernels import broad_phase as kb
from polycontact._kernels import impact as ki
from polycontact._kernels.advance import edge_table, pair_step, traversal_stack, window_kinematics

ULPS = 64 * 2.0**-52
vec = st.tuples(st.floats(-3, 3), st.floats(-3, 3))
small = st.floats(-10, 10, allow_nan=False).map(lambda x: 0.0 if abs(x) < 1e-3 else x)


def _motion_pair(d0, dv, acc):
    """Centroids and motion vectors with relative motion D(t) = d0 + dv t + acc t²/2."""
    ca, cb = np.array(d0, float), np.zeros(2)
    ma = np.array([dv[0], dv[1], acc[0], acc[1], 0.0, 0.0])
    return ca, ma, cb, np.zeros(6)


def _reference_nonpositive(d0, dv, acc, r, lo, hi):
    """Where |D(t)| <= r, from numpy.roots of the expanded quartic and the sign between
    roots (fine for coordinates of order 1)."""
    d0, dv, h = np.array(d0, float), np.array(dv, float), 0.5 * np.array(acc, float)
    c = np.array([d0 @ d0 - r * r, 2 * d0 @ dv, dv @ dv + 2 * h @ d0, 2 * h @ dv, h @ h])
    roots = np.roots(c[::-1]) if np.any(c[1:]) else np.array([])
    real = sorted(x.real for x in roots if abs(x.imag) < 1e-9 and lo < x.real < hi)
    pts = [lo, *real, hi]
    val = lambda t: np.hypot(*(d0 + dv * t + h * t * t)) - r
    return [(s, e) for s, e in zip(pts, pts[1:]) if val(0.5 * (s + e)) <= 0], val


@given(st.tuples(small, small), st.tuples(small, small), st.tuples(small, small),
       st.floats(0.1, 5))
def test_nonpositive_intervals_match_numpy_roots(d0, dv, acc, r):
    ca, ma, cb, mb = _motion_pair(d0, dv, acc)
    p = kb.relative_motion(ca, ma, cb, mb)
    out = kb.nonpositive_intervals(p, r, 0.0, 3.0)
    ref, val = _reference_nonpositive(d0, dv, acc, r, 0.0, 3.0)
    for s, e in out:
        assert 0.0 <= s <= e <= 3.0
        assert val(0.5 * (s + e)) <= 1e-9 * (1 + np.abs(d0).sum() + 9 * np.abs(acc).sum())
    for s, e in ref:
        m = 0.5 * (s + e)
        if val(m) < -1e-6:
            assert any(a - 1e-9 <= m <= b + 1e-9 for a, b in out)


@given(st.tuples(small, small), st.tuples(small, small), st.tuples(small, small),
       st.floats(0.1, 5))
def test_interval_ends_are_sign_changes_to_adjacent_floats(d0, dv, acc, r):
    # the root finder (false position and halving) must still end, at every end
    # strictly inside [0, 3], on an exact zero of |D(t)| - r or on a sign change of it
    # between adjacent floats
    ca, ma, cb, mb = _motion_pair(d0, dv, acc)
    p = kb.relative_motion(ca, ma, cb, mb)
    f = lambda t: kb.derivative(p, r, 0, t) <= 0.0  # noqa: E731
    for x in kb.nonpositive_intervals(p, r, 0.0, 3.0).ravel():
        if 0.0 < x < 3.0:
            below, above = np.nextafter(x, -np.inf), np.nextafter(x, np.inf)
            assert kb.derivative(p, r, 0, x) == 0.0 or f(below) != f(x) or f(x) != f(above)


@given(st.tuples(small, small), st.tuples(small, small), st.tuples(small, small))
def test_distance_is_monotone_between_breakpoints(d0, dv, acc):
    ca, ma, cb, mb = _motion_pair(d0, dv, acc)
    p = kb.relative_motion(ca, ma, cb, mb)
    pts = kb.monotone_breakpoints(p, -2.0, 2.0)
    assert pts[0] == -2.0 and pts[-1] == 2.0 and np.all(np.diff(pts) >= 0)
    for s, e in zip(pts, pts[1:]):
        ts = np.linspace(s, e, 9)
        d = np.diff([np.hypot(*(np.array(d0) + np.array(dv) * t + 0.5 * np.array(acc) * t * t))
                     for t in ts])
        scale = 1e-9 * (1 + np.abs(d0).sum() + np.abs(dv).sum() * 4 + np.abs(acc).sum() * 8)
        assert np.all(d >= -scale) or np.all(d <= scale)


def test_grazing_is_a_point_interval():
    # |D(t)| = |(t - 1, 1)| touches r = 1 at t = 1 only
    p = kb.relative_motion(np.array([-1.0, 1.0]), np.array([1.0, 0, 0, 0, 0, 0]),
                           np.zeros(2), np.zeros(6))
    out = kb.nonpositive_intervals(p, 1.0, 0.0, 3.0)
    assert out.shape == (1, 2) and abs(out[0, 0] - 1) < 1e-7 and abs(out[0, 1] - 1) < 1e-7


def test_no_relative_motion():
    still = np.zeros(6)
    p = kb.relative_motion(np.array([1.0, 0.0]), still, np.zeros(2), still)
    assert kb.nonpositive_intervals(p, 2.0, 0.0, 2.0).tolist() == [[0.0, 2.0]]
    assert kb.nonpositive_intervals(p, 0.5, 0.0, 2.0).shape == (0, 2)


def test_intervals_stay_right_at_long_travel():
    # unit circles 1e9 apart (0.3 off the line), closing at 1 unit/s: the expanded
    # quartic (d0² = 1e18) lost R² and gave a single instant; relative coordinates keep
    # the roots to the float spacing of the positions (1.2e-7 at 1e9)
    r = 2 * math.sqrt(0.5)
    half = math.sqrt(r * r - 0.09)
    for offset in (0.0, 1e9):
        ca, cb = np.array([offset, 0.0]), np.array([offset + 1e9, 0.3])
        ma = np.array([1.0, 0, 0, 0, 0, 0])
        out = kb.overlap_intervals(ca, ma, r / 2, cb, np.zeros(6), r / 2, 2e9, 1e-12)
        slack = 2 * kb.rounding_allowance(ca, ma, cb, np.zeros(6), 2e9) + 1e-6  # ~ 4e-5
        assert out.shape == (1, 2)
        assert 1e9 - half - slack <= out[0, 0] <= 1e9 - half
        assert 1e9 + half <= out[0, 1] <= 1e9 + half + slack


@given(st.floats(0, 1e9), st.floats(-1e9, 1e9), st.floats(1e-6, 1e12),
       st.floats(-1.0, 1.0), st.floats(0.0, 1e3))
def test_intervals_hold_every_overlap_far_away(gap, offset, speed, lateral, acc):
    """Long travel, far offsets, any speed, with acceleration: the circles of radius 1
    overlap exactly while |D(t)| <= 2; the intervals contain every such instant (checked
    at the true entry and exit, computed in closed form without acceleration, and at
    dense samples with it) and are no wider than the rounding allowance."""
    r = 1.0
    ca = np.array([offset, offset])
    cb = np.array([offset + 2 * r + gap, offset + lateral])
    ma = np.array([speed, 0.0, acc, 0.0, 0.0, 0.0])
    t_max = 4 * (2 * r + gap) / speed + 1.0
    out = kb.overlap_intervals(ca, ma, r, cb, np.zeros(6), r, t_max, 1e-12)
    allowance = kb.rounding_allowance(ca, ma, cb, np.zeros(6), t_max) + 4e-12
    d0 = ca - cb

    def dist(t):
        return math.hypot(d0[0] + speed * t + 0.5 * acc * t * t, d0[1])

    inside = lambda t: any(s <= t <= e for s, e in out)
    for t in np.linspace(0.0, t_max, 2001):
        if dist(t) <= 2 * r:
            assert inside(t)
        elif dist(t) > 2 * r + 2 * allowance + 1e-9 * dist(t):
            assert not inside(t)




@given(vec, vec, st.floats(-4, 4), st.floats(-4, 4), st.floats(0, 3))
def test_place_matches_shape_moved(v, a, w, al, t):
    tri = Shape([(0, 0), (2, 0.5), (0.5, 1.5)])
    m = Motion(v, a, w, al)
    out = np.empty_like(tri.packed[0])
    ki.place(tri.packed[0] - tri.centroid, np.array(tri.centroid), m.array, t, out)
    assert np.allclose(out, tri.at(m, t).exterior, atol=1e-12)


@given(vec, vec, st.floats(-4, 4), st.floats(-4, 4), vec, vec, st.floats(-4, 4),
       st.floats(-4, 4), st.floats(0, 2), st.floats(0.0, 0.5))
def test_speed_bound_bounds_every_vertex_speed(va, aa, wa, ala, vb, ab, wb, alb, t0, dt):
    a = Shape([(0, 0), (2, 0.5), (0.5, 1.5)])
    b = Shape([(0, 0), (1, 0), (1, 3), (0, 3)])
    ma, mb = Motion(va, aa, wa, ala), Motion(vb, ab, wb, alb)
    bound = ki.speed_bound(ma.array, a.bounding_radius, mb.array, b.bounding_radius,
                           t0, t0 + dt)
    h = 1e-6
    for t in np.linspace(t0, t0 + dt, 5):
        pa = (a.at(ma, t + h).exterior - a.at(ma, t - h).exterior) / (2 * h)
        pb = (b.at(mb, t + h).exterior - b.at(mb, t - h).exterior) / (2 * h)
        rel = pa[:, None, :] - pb[None, :, :]
        assert np.max(np.hypot(rel[..., 0], rel[..., 1])) <= bound * (1 + 1e-6) + 1e-6


def _kernel_args(a, ma, b, mb):
    """``(body_a, motion_a, body_b, motion_b)`` as the search kernels take them."""
    return ((a.packed[0] - a.centroid, a.packed[1], np.array(a.centroid), a.bounding_radius),
            ma.array,
            (b.packed[0] - b.centroid, b.packed[1], np.array(b.centroid), b.bounding_radius),
            mb.array)


def test_exact_search_on_flush_squares():
    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    b = sq.moved((3, 0))
    iv = np.array([[0.0, 5.0]])
    code, hi, lo, contact, its, reached = ki.exact_search(
        *_kernel_args(sq, Motion(velocity=(1, 0)), b, Motion()), iv,
        (1e-4, 1e-12, ULPS, 1e-6, 10000))
    assert code == ki.HIT and lo < hi and hi - lo <= 1e-4 and abs(hi - 2.0) <= 1e-4
    assert lo <= 2.0 <= hi and contact <= hi


@given(vec, st.floats(-1, 1), vec, st.floats(0.0, 2.0), st.floats(-3.0, 3.0))
@example((1.0, 0.0), 0.0, (0.0, 0.0), 1.5, 0.0)   # apart, circles overlapping at t = 0
@example((-2.0, 0.0), 0.0, (0.0, 0.0), 0.5, 0.0)  # penetrating at t = 0
def test_query_in_two_steps_answers_as_exact_query(va, wa, vb, gap, dy):
    # the broad phase (query_intervals) then the search (query_search) give what
    # exact_query gives; a caller that has found the bodies apart at t = 0 may say so,
    # and then gets the same answer without the search classifying them there again
    sq = Shape([(0, 0), (2, 0), (2, 2), (1, 1), (0, 2)])
    b = Shape([(0, 0), (1, 0), (1, 1), (0, 1)]).moved((2.0 + gap - 1.0, dy))
    a_, ma, b_, mb = _kernel_args(sq, Motion(velocity=va, angular_velocity=wa), b,
                                  Motion(velocity=vb))
    ea, eb = edge_table(a_[0], a_[1]), edge_table(b_[0], b_[1])
    query = (3.0, 1e-12, 1e-4, 1e-12, ULPS, 1e-6, 100_000, 0)
    work = np.empty(ki.work_floats(a_[0].shape[0] + b_[0].shape[0]))
    whole = ki.exact_query(a_, ea, ma, b_, eb, mb, query, work)
    n = ki.query_intervals(a_[2], ma, a_[3], b_[2], mb, b_[3], query[0], query[1], work)
    assert n == whole[0]
    assert ki.query_search(a_, ea, ma, b_, eb, mb, n, query, work, False) == whole[1:]
    if whole[1] != ki.INITIALLY_PENETRATING:
        n = ki.query_intervals(a_[2], ma, a_[3], b_[2], mb, b_[3], query[0], query[1], work)
        assert ki.query_search(a_, ea, ma, b_, eb, mb, n, query, work, True) == whole[1:]


def test_a_speed_too_small_to_bound_the_window_leaves_it_unbounded_without_overflow():
    """A subnormal speed far from the origin: the window over which the tolerances stay
    local is longer than any float, and local_end says so without overflowing."""
    still = np.zeros(6)
    crawl = np.array([5e-324, 0.0, 0.0, 5e-324, 0.0, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        end = ki.local_end(np.array([1e300, 0.0]), crawl, 1.0, np.array([1e300, 3.0]), still,
                           1.0, 0.0)
    assert end == np.inf


def test_exact_search_reports_the_budget():
    # a square spinning in a square hole it fits exactly, the holed body spinning with
    # it a hair faster: in contact throughout, turning apart by far less than the
    # tolerance, while each body's own spin is all the bounds see, so the touch is
    # stepped through by probes
    sq = Shape([(-1, -1), (1, -1), (1, 1), (-1, 1)])
    b = Shape([(-3, -3), (3, -3), (3, 3), (-3, 3)], [[(-1, -1), (-1, 1), (1, 1), (1, -1)]])
    out = ki.exact_search(*_kernel_args(sq, Motion(angular_velocity=1.0), b,
                                        Motion(angular_velocity=1.0 + 1e-13)),
                          np.array([[0.0, 1.0]]), (1e-4, 1e-12, ULPS, 1e-3, 50))
    assert out[0] == ki.OUT_OF_ITERATIONS and out[3] == 0.0 and out[5] < 1.0


def test_exact_search_answers_at_once_without_relative_motion():
    # the same square and hole spinning together: B keeps its pose in A's frame, so the
    # contact at t = 0 holds throughout, however fast they turn
    sq = Shape([(-1, -1), (1, -1), (1, 1), (-1, 1)])
    b = Shape([(-3, -3), (3, -3), (3, 3), (-3, 3)], [[(-1, -1), (-1, 1), (1, 1), (1, -1)]])
    for spin in (Motion(angular_velocity=50.0), Motion((3.0, -1.0), (0.5, 2.0), 7.0, 1.0)):
        code, hi, lo, contact, its, reached = ki.exact_search(
            *_kernel_args(sq, spin, b, spin), np.array([[0.0, 100.0]]),
            (1e-4, 1e-12, ULPS, 1e-6, 1_000_000))
        assert (code, contact) == (ki.NO_HIT, 0.0) and its == 1
    # apart, a common translation keeps them apart; a common spin about two centres
    # moves B in A's frame: not answered at once
    far = sq.moved((5.0, 0.0))
    drift = Motion((1.0, 2.0), (0.0, -1.0))
    assert ki.exact_search(*_kernel_args(sq, drift, far, drift), np.array([[0.0, 100.0]]),
                           (1e-4, 1e-12, ULPS, 1e-6, 1_000_000))[0] == ki.NO_HIT
    args = _kernel_args(sq, Motion(angular_velocity=1.0), far, Motion(angular_velocity=1.0))
    assert not ki.fixed_relative_pose(args[0][2], args[1], args[0][3], args[2][2], args[3],
                                      args[2][3], ULPS)


def test_exact_search_follows_a_slide_under_an_overhang():
    # sliding contact from t = 0 under an overhang whose leg reaches below A's top (no
    # line separates the bodies): the touching pairs keep to their edges' lines, so the
    # slide is stepped over, and the hit on the leg at t = 0.8 is found in a few steps
    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    b = Shape([(0.5, 1), (1.8, 1), (1.8, 0), (2.1, 0), (2.1, 2), (0.5, 2)])
    out = ki.exact_search(*_kernel_args(sq, Motion(velocity=(1, 0)), b, Motion()),
                          np.array([[0.0, 1.0]]), (1e-4, 1e-12, ULPS, 1e-3, 50))
    # (an overlap up to the tolerance eps = 1e-12 is contact, so the first penetration
    # beyond it is at 0.8 + eps / v)
    assert out[0] == ki.HIT and out[2] <= 0.8 + 1e-12 <= out[1] and out[1] - out[2] <= 1e-4
    assert out[3] == 0.0 and out[4] < 10


def test_exact_search_follows_a_slide_in_few_steps():
    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    b = Shape([(0.5, 1), (9, 1), (9, 2), (0.5, 2)])   # sliding contact from t = 0
    out = ki.exact_search(*_kernel_args(sq, Motion(velocity=(1, 0)), b, Motion()),
                          np.array([[0.0, 12.0]]), (1e-4, 1e-12, ULPS, 1e-3, 50))
    assert out[0] == ki.NO_HIT and out[3] == 0.0 and out[4] < 50


@given(vec, st.floats(-0.3, 0.3), vec, st.floats(-0.3, 0.3), st.floats(0.0, 1.0),
       st.floats(0.0, 1.0))
def test_slide_time_keeps_the_interiors_apart(va, wa, vb, wb, dx, frac):
    """Whatever the motions, during the certified time a square resting on a bar
    (flush, at an offset dx) does not come to overlap it (Shapely, beyond rounding)."""
    a = Shape([(0, 0), (1, 0), (1, 1), (0, 1)]).moved((dx, 0))
    bar = Shape([(-1, -0.5), (3, -0.5), (3, 0), (-1, 0)])
    ma, mb = Motion(va, angular_velocity=wa), Motion(vb, angular_velocity=wb)
    ra, rb = a.packed[0] - a.centroid, bar.packed[0] - bar.centroid
    la, lb = np.hypot(*ra.T), np.hypot(*rb.T)
    na, nb = edge_table(ra, a.packed[1])[0], edge_table(rb, bar.packed[1])[0]
    mva, mvb, kin, _ = window_kinematics(ma.array, mb.array, 0.0, 1.0)
    # A's vertices against the line of the bar's top edge (edge 2: (3, 0) -> (-1, 0))
    h = ki.slide_time((a.packed[0], np.array(a.centroid), mva, la, na, a.bounding_radius),
                      (bar.packed[0], np.array(bar.centroid), mvb, lb, nb, bar.bounding_radius),
                      2, kin, 1e-12, 1.0, 0.0, 0)
    assert 0.0 <= h <= 1.0
    if va == vb == (0.0, 0.0) and wa == wb == 0.0:
        assert h == 1.0                 # nothing moves: the whole window
    t = h * frac
    overlap = a.at(ma, t).to_shapely().intersection(bar.at(mb, t).to_shapely()).area
    assert overlap <= 1e-9


def _paper_sampled(a, ma, b, mb, t1, t2, n, threshold):
    """The paper's §3 steps 3–6 with Shapely deciding penetration."""
    def pen(t):
        return shapely.relate_pattern(a.at(ma, t).to_shapely(), b.at(mb, t).to_shapely(),
                                      "2********")
    found = False
    while True:
        ts = [t1 + i * (t2 - t1) / (n - 1) for i in range(n - 1)] + [t2]
        t0 = next((t for t in ts if pen(t)), None)
        if t0 is None:
            return t2 if found else None
        found = True
        t1, t2 = max(t0 - (t2 - t1) / n, 0.0), t0
        if t2 - t1 < threshold:
            return t2


def test_sampled_search_follows_the_paper_steps():
    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    b = Shape([(3, 0.5), (4, 0), (4, 1)])
    for n in (2, 3, 10):
        m_a = Motion(velocity=(1, 0.1), angular_velocity=0.3)
        code, hi, lo, contact, evals = ki.sampled_search(
            *_kernel_args(sq, m_a, b, Motion()), np.array([[0.5, 4.0]]), 1e-3, n, 1e-12, ULPS,
            1_000_000)
        expected = _paper_sampled(sq, m_a, b, Motion(), 0.5, 4.0, n, 1e-3)
        assert code == ki.HIT and math.isclose(hi, expected, abs_tol=1e-12)


@given(vec, st.floats(-4, 4), vec, st.floats(-4, 4), st.floats(-1, 1), st.floats(0, 1))
@example((0.0, 0.0), 0.0, (-1.0, 0.0), 0.0, 0.0, 0.9999999999999999)
def test_pair_step_distance_and_soundness(va, wa, vb, wb, dy, frac):
    from polycontact._kernels.distance import boundary_distance

    a = Shape([(0, 0), (2, 0.5), (1, 0.7), (0.5, 1.5)])
    b = Shape([(0, 0), (1, 0), (1, 3), (0.5, 1), (0, 3)]).moved((3.0, dy))
    ma, mb = Motion(va, angular_velocity=wa), Motion(vb, angular_velocity=wb)
    ra, rb = a.packed[0] - a.centroid, b.packed[0] - b.centroid
    ea, eb = edge_table(ra, a.packed[1]), edge_table(rb, b.packed[1])
    d, step = pair_step((ra, ea), np.array(a.centroid), ma.array, (rb, eb), np.array(b.centroid),
                        mb.array, (0.0, 1.0), (0.0, 0.0, 0.0), np.full(3, -1), traversal_stack())
    # the distance is exact up to lam (pairs that cannot matter are skipped): with lam = 0
    # it is never below the gap, and with lam just above the gap it is the gap
    gap = boundary_distance(*a.packed, *b.packed)
    assert d >= gap * (1 - 1e-12)
    d_lam, _ = pair_step((ra, ea), np.array(a.centroid), ma.array, (rb, eb),
                         np.array(b.centroid), mb.array, (0.0, 1.0), (1.01 * gap, 0.0, 0.0),
                         np.full(3, -1), traversal_stack())
    assert math.isclose(d_lam, gap, rel_tol=1e-12)
    speed = ki.speed_bound(ma.array, a.bounding_radius, mb.array, b.bounding_radius,
                           0.0, 1.0)
    if speed > 0:
        assert step >= min(1.0, d / speed * (1 - 1e-12))
    t = min(step, 1.0) * frac
    moved = boundary_distance(*a.at(ma, t).packed, *b.at(mb, t).packed)
    # Short of the step the bodies are still apart, unless the gap left, (1 - frac) d,
    # is below the rounding of the placed coordinates (frac = 1 - 1e-16 on a head-on
    # approach leaves a gap of 1e-16).
    assert moved > 0 or (1 - frac) * d < 1e-12


def _star(n, r0, r1, phase):
    ang = phase + np.arange(2 * n) * math.pi / n
    rad = np.where(np.arange(2 * n) % 2 == 0, r0, r1)
    return Shape(np.column_stack([rad * np.cos(ang), rad * np.sin(ang)]))


@given(vec, vec, st.floats(-6, 6), st.floats(-6, 6), vec, st.floats(-6, 6), st.floats(-6, 6),
       st.floats(-0.5, 0.5), st.floats(0.05, 2.0), st.sampled_from([3, 12]))
def test_pair_step_keeps_every_pair_apart(va, aa, wa, ala, vb, wb, alb, dy, window, n):
    """The directional step (both the all-pairs scan and, with 12-point stars, the
    sorted sweep) never lets the boundaries come within lam, with turning, spinning
    and accelerating bodies."""
    from polycontact._kernels.distance import boundary_distance

    a = _star(n, 1.0, 0.6, 0.1)
    b = _star(n, 0.8, 0.5, 0.3).moved((2.4, dy))
    ma, mb = Motion(va, aa, wa, ala), Motion(vb, (0, 0), wb, alb)
    t0 = 0.3
    pa, pb = a.at(ma, t0), b.at(mb, t0)
    ra, rb = a.packed[0] - a.centroid, b.packed[0] - b.centroid
    lam = 1e-3
    lam_pair = ki.PAIR_GAP * lam
    d, step = pair_step((ra, edge_table(ra, a.packed[1])), np.array(pa.centroid), ma.array,
                        (rb, edge_table(rb, b.packed[1])), np.array(pb.centroid), mb.array,
                        (t0, t0 + window), (lam, lam_pair, 0.0), np.full(3, -1),
                        traversal_stack())
    gap = boundary_distance(*pa.packed, *pb.packed)
    assume(gap > lam)                  # apart at t0 (the step starts from no contact)
    assert 0.0 <= step <= (t0 + window) - t0 and d >= gap * (1 - 1e-12)
    for t in np.linspace(t0, t0 + step, 7):
        assert boundary_distance(*a.at(ma, t).packed, *b.at(mb, t).packed) >= lam_pair * (1 - 1e-9)


@examples(50)
@given(st.integers(3, 40), st.integers(0, 3), st.floats(-1e9, 1e9), st.floats(1e-9, 1e9))
def test_a_packed_body_unpacks_to_its_arrays(n, holes, offset, radius):
    # exact_call takes each body as pack_body's two arrays: unpacked, they must be the
    # arrays exact_query takes, bit for bit (loops of several lengths, holes)
    rng = np.random.default_rng(n * 7 + holes)
    sizes = [n] + [3 + k for k in range(holes)]
    r = rng.normal(size=(sum(sizes), 2)) * radius + offset
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    table = edge_table(r, starts)
    centroid = np.array([offset, -offset])
    f, i = ki.pack_body(r, starts, centroid, radius, table)
    (r2, s2, c2, rad2), table2 = ki.unpack_body(f, i)
    assert np.array_equal(r2, r) and np.array_equal(s2, starts)
    assert np.array_equal(c2, centroid) and rad2 == radius
    for got, want in zip(table2, table):
        assert got.dtype == want.dtype and np.array_equal(got, want)
