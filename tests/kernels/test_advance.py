"""The step kernel of the exact time-of-impact search: its tree of circles and its
second-order bounds, each checked against dense sampling of the true motion.

Small inputs: this file also runs with NUMBA_DISABLE_JIT=1 (see .ci/run).
"""

import itertools
import math

import numpy as np
import shapely
from hypothesis import assume, example, given
from hypothesis import strategies as st

from polycontact._kernels import advance as ka

coord = st.floats(-50, 50, allow_nan=False)
rate = st.floats(-4, 4)


def _leaves(links, k):
    if links[k, 2] >= 0:
        return [int(links[k, 2])]
    return _leaves(links, links[k, 0]) + _leaves(links, links[k, 1])


@given(st.integers(3, 40), st.integers(0, 2 ** 31), st.booleans())
def test_edge_table_circles_hold_their_edges(n, seed, with_hole):
    """Any loops will do (the table does not need a valid shape): every edge is under one
    leaf, and every node's circle holds the ends of the edges under it."""
    rng = np.random.default_rng(seed)
    loops = [rng.normal(size=(n, 2)) * rng.uniform(0.1, 100)]
    if with_hole:
        loops.append(rng.normal(size=(4, 2)))
    r = np.concatenate(loops)
    starts = np.cumsum([0] + [len(loop) for loop in loops])
    nxt, links, circles, r_len = ka.edge_table(r, starts)
    for k in range(len(starts) - 1):           # edges close each loop
        assert list(nxt[starts[k]:starts[k + 1]]) == [*range(starts[k] + 1, starts[k + 1]),
                                                      starts[k]]
    assert sorted(_leaves(links, 0)) == list(range(len(r)))   # each edge under one leaf
    np.testing.assert_allclose(r_len, np.hypot(*r.T))
    for k in range(len(links)):
        ends = np.array([r[v] for e in _leaves(links, k) for v in (e, nxt[e])])
        assert np.all(np.hypot(*(ends - circles[k, :2]).T) <= circles[k, 2])
        assert math.isclose(circles[k, 3], math.hypot(*circles[k, :2]))


def _smallest_radius_by_enumeration(pts):
    """The smallest enclosing circle by brute force: it passes through two points (as a
    diameter) or three (their circumcircle); the smallest candidate holding all."""
    pts = np.unique(pts, axis=0)
    if len(pts) == 1:
        return 0.0
    scale = np.abs(pts).max()
    best = np.inf
    cands = [((p + q) / 2, np.hypot(*(p - q)) / 2) for p, q in itertools.combinations(pts, 2)]
    for p, q, r in itertools.combinations(pts, 3):
        d = 2 * ((q - p)[0] * (r - p)[1] - (q - p)[1] * (r - p)[0])
        if abs(d) > 1e-9 * scale * scale:
            a2, b2 = np.dot(q - p, q - p), np.dot(r - p, r - p)
            c = p + np.array([(r - p)[1] * a2 - (q - p)[1] * b2,
                              (q - p)[0] * b2 - (r - p)[0] * a2]) / d
            cands.append((c, np.hypot(*(p - c))))
    for c, rad in cands:
        if rad < best and np.all(np.hypot(*(pts - c).T) <= rad * (1 + 1e-9) + 1e-12 * scale):
            best = rad
    return best


@given(st.lists(st.tuples(coord, coord), min_size=1, max_size=12), st.integers(0, 1000),
       st.booleans())
@example([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.0, 0.0)], 0, False)   # collinear, repeated
@example([(0.0, 0.0), (0.0, -1.0), (1.0, 0.0), (2.5e-55, -1.0)], 0, False)  # (GEOS: 0.5)
def test_smallest_circle_is_the_smallest(points, seed, collinear):
    pts = np.array(points, dtype=float)
    if collinear:
        pts[:, 1] = 0.5 * pts[:, 0] + 3.0
    px, py = pts[:, 0].copy(), pts[:, 1].copy()
    cx, cy = ka._smallest_circle(px, py, len(pts), seed)
    radius = np.hypot(pts[:, 0] - cx, pts[:, 1] - cy).max()
    best = _smallest_radius_by_enumeration(pts)
    assert radius <= best * (1 + 1e-9) + 1e-9 * max(1.0, np.abs(pts).max())


@given(st.floats(1e-6, 10), st.floats(-10, 10), st.floats(0, 100), st.floats(1e-6, 5))
def test_root_is_the_first_zero_of_the_parabola(g, r, k, cap):
    tau = ka._root(g, r, k, cap)
    assert 0.0 <= tau <= cap
    f = lambda s: g + r * s - 0.5 * k * s * s
    s = np.linspace(0.0, tau, 64)[:-1]
    assert np.all(f(s) > -1e-12 * (1 + abs(r) * cap + k * cap * cap))
    if tau < cap:
        assert abs(f(tau)) <= 1e-9 * (g + abs(r) * tau + k * tau * tau)


# -- the bounds against the true motion -------------------------------------------------
def _pose(c0, m, t):
    """Centroid, rotation angle, velocity and angular velocity at t (m as Motion.array)."""
    c = c0 + m[:2] * t + 0.5 * m[2:4] * t * t
    return c, m[4] * t + 0.5 * m[5] * t * t, m[:2] + m[2:4] * t, m[4] + m[5] * t


def _placed(c0, m, r, t):
    c, th, _, _ = _pose(c0, m, t)
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    return c + r @ rot.T


def _kin(mv, me, t0, t1):
    """The window tuple of ``_vertex_edge_time`` / ``_node_time``, as ``pair_step`` builds
    it: (|Δa|, |α_v| + ω_v,max², |α_e| + ω_e,max², max |Δv|, ω_v,max, ω_e,max, Δax,
    Δay)."""
    wv = max(abs(mv[4] + mv[5] * t0), abs(mv[4] + mv[5] * t1))
    we = max(abs(me[4] + me[5] * t0), abs(me[4] + me[5] * t1))
    dv = [np.hypot(*(mv[:2] - me[:2] + (mv[2:4] - me[2:4]) * t)) for t in (t0, t1)]
    dax, day = mv[2:4] - me[2:4]
    return (float(np.hypot(dax, day)), abs(mv[5]) + wv * wv, abs(me[5]) + we * we, max(dv), wv,
            we, float(dax), float(day))


def _segment_distance(p, a, b):
    d = b - a
    s = np.clip(np.dot(p - a, d) / np.dot(d, d), 0.0, 1.0)
    return float(np.hypot(*(p - a - s * d)))


motion = st.tuples(rate, rate, rate, rate, st.floats(-6, 6), st.floats(-6, 6))


@given(motion, motion, st.tuples(coord, coord), st.tuples(coord, coord), st.tuples(coord, coord),
       st.floats(0.0, 2.0), st.floats(0.01, 2.0))
def test_vertex_edge_time_keeps_the_pair_apart(mv, me, rp, ra, rb, t0, cap):
    """Whatever the accelerations and spins, the vertex stays more than lam from the
    edge for the whole time the bound grants (dense sampling of the true motion)."""
    mv, me = np.array(mv), np.array(me)
    rp, ra, rb = (np.array(v) * 0.1 for v in (rp, ra, rb))
    assume(np.hypot(*(rb - ra)) > 1e-3)
    cv0, ce0 = np.array([0.0, 0.0]), np.array([6.0, 0.0])
    lam = 1e-3
    cv, _, vv, wv = _pose(cv0, mv, t0)
    ce, _, ve, we = _pose(ce0, me, t0)
    p = _placed(cv0, mv, rp[None], t0)[0]
    a, b = _placed(ce0, me, np.array([ra, rb]), t0)
    assume(_segment_distance(p, a, b) > lam)
    vel = vv + wv * np.array([-(p[1] - cv[1]), p[0] - cv[0]])
    d2, tau = ka._vertex_edge_time((p[0], p[1], vel[0], vel[1], np.hypot(*rp)), a[0], a[1],
                                   b[0], b[1], np.hypot(*ra), np.hypot(*rb),
                                   (ce[0], ce[1], ve[0], ve[1], we),
                                   _kin(mv, me, t0, t0 + cap), lam, cap, 0.0)
    assert math.isclose(math.sqrt(d2), _segment_distance(p, a, b), rel_tol=1e-9)
    assert 0.0 <= tau <= cap
    for t in np.linspace(t0, t0 + tau, 200):
        q = _placed(cv0, mv, rp[None], t)[0]
        ea, eb = _placed(ce0, me, np.array([ra, rb]), t)
        assert _segment_distance(q, ea, eb) >= lam * (1 - 1e-9) - 1e-12


@given(motion, motion, st.tuples(coord, coord), st.tuples(coord, coord), st.floats(0.0, 3.0),
       st.floats(0.0, 3.0), st.floats(0.0, 2.0), st.floats(0.01, 2.0))
def test_node_time_keeps_the_circles_apart(ma, mb, ra, rb, rho_a, rho_b, t0, cap):
    """Two circles turning with their bodies stay more than lam apart for the time
    the node bound grants."""
    ma, mb = np.array(ma), np.array(mb)
    ra, rb = np.array(ra) * 0.1, np.array(rb) * 0.1
    ca0, cb0 = np.array([0.0, 0.0]), np.array([12.0, 1.0])
    lam = 1e-3
    qa = np.array([[ra[0], ra[1], rho_a, np.hypot(*ra)]])
    qb = np.array([[rb[0], rb[1], rho_b, np.hypot(*rb)]])
    ca, tha, va, wa = _pose(ca0, ma, t0)
    cb, thb, vb, wb = _pose(cb0, mb, t0)
    gap = lambda t: (np.hypot(*(_placed(ca0, ma, ra[None], t)[0] - _placed(cb0, mb, rb[None], t)[0]))
                     - rho_a - rho_b)
    assume(gap(t0) > lam)
    tau = ka._node_time(qa, 0, (ca, math.cos(tha), math.sin(tha), va[0], va[1], wa), qb, 0,
                        (cb, math.cos(thb), math.sin(thb), vb[0], vb[1], wb),
                        _kin(ma, mb, t0, t0 + cap), lam, cap)
    assert 0.0 <= tau <= cap
    for t in np.linspace(t0, t0 + tau, 200):
        assert gap(t) >= lam * (1 - 1e-9) - 1e-12


@given(st.floats(1, 5), st.floats(-2, 2), st.floats(2e-3, 0.5), st.floats(-1, 1),
       st.floats(-20, 20), st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3),
       st.tuples(st.floats(-1, 1), st.floats(-1, 1)), st.floats(0.01, 1.0),
       st.floats(-20, 20))
def test_vertex_edge_time_along_a_turning_line(half, y0, s0, x, slide, we, ae, wv, rp, cap,
                                               push):
    """A vertex just outside an edge's line, sliding fast along it (and pushed along it)
    while the edge's body turns: the case where the bound towards the turning line is
    the longer one (its Coriolis and centripetal terms, and the push turning across
    the line, matter)."""
    lam = 1e-3
    ce0 = np.array([0.0, 0.0])
    ra, rb = np.array([-half, y0]), np.array([half, y0])     # interior above (on the left)
    rp = np.array(rp) * 0.5
    p0 = np.array([x * half, y0 - s0])
    cv0 = p0 - rp
    mv = np.array([slide, 0.0, push, 0.0, wv, 0.0])
    me = np.array([0.0, 0.0, 0.0, 0.0, we, ae])
    vel = mv[:2] + wv * np.array([-rp[1], rp[0]])
    d2, tau = ka._vertex_edge_time((p0[0], p0[1], vel[0], vel[1], np.hypot(*rp)), ra[0], ra[1],
                                   rb[0], rb[1], np.hypot(*ra), np.hypot(*rb),
                                   (0.0, 0.0, 0.0, 0.0, we), _kin(mv, me, 0.0, cap), lam, cap,
                                   0.0)
    assert 0.0 <= tau <= cap
    for t in np.linspace(0.0, tau, 400):
        q = _placed(cv0, mv, rp[None], t)[0]
        ea, eb = _placed(ce0, me, np.array([ra, rb]), t)
        assert _segment_distance(q, ea, eb) >= lam * (1 - 1e-9) - 1e-12


def _placed_polygon(shape, motion, t):
    return shapely.Polygon(_placed(np.asarray(shape.centroid), motion.array,
                                   shape.exterior - shape.centroid, t))


@given(st.floats(-2, 2), st.floats(-0.3, 0.3), st.floats(-0.5, 0.5), st.floats(-1, 1),
       st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-0.8, 0.8), st.floats(0.05, 1.0))
@example(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)        # a pure slide under the overhang
def test_touching_step_allows_no_penetration_deeper_than_touch(vx, vy, wa, ax, wb, ay, dx,
                                                              window):
    """Bodies touching flush (a block on a floor under an overhang, so no line separates
    them), moving at random, spinning and accelerating: during the step granted with
    ``touch``, neither body gets deeper than about ``touch`` into the other (Shapely:
    the other body shrunk by 2·touch is never met)."""
    from polycontact import Motion, Shape

    block = Shape([(0, 0), (1, 0), (1, 1), (0, 1)]).moved((dx, 0.0))
    floor = Shape([(-3, -1), (2.3, -1), (2.3, 1.5), (2.0, 1.5), (2.0, 0), (-3, 0)])
    ma = Motion((vx, vy), (ax, ay), wa, 0.0)
    mb = Motion((0.0, 0.0), (0.0, 0.0), wb, 0.0)
    ra, rb = block.packed[0] - block.centroid, floor.packed[0] - floor.centroid
    lam, touch = 1e-3, 1e-4
    _, step = ka.pair_step((ra, ka.edge_table(ra, block.packed[1])), np.array(block.centroid),
                           ma.array, (rb, ka.edge_table(rb, floor.packed[1])),
                           np.array(floor.centroid), mb.array, (0.0, window),
                           (lam, lam / 64, touch), np.full(3, -1), ka.traversal_stack())
    assert 0.0 <= step <= window
    for t in np.linspace(0.0, step, 40):
        pa, pb = _placed_polygon(block, ma, t), _placed_polygon(floor, mb, t)
        assert not shapely.intersects(pa, pb.buffer(-2 * touch, join_style="mitre"))
        assert not shapely.intersects(pb, pa.buffer(-2 * touch, join_style="mitre"))
