"""Many moving bodies: time_of_impact_many and first_impacts against the pairwise calls.

The oracle is the pairwise ``time_of_impact`` itself (its own correctness is checked
against Shapely in test_impact.py): every batched answer must be *equal* to it (the
same Impact, field by field), and ``first_impacts`` must find exactly the pairs that
the brute force over all pairs finds. The swept bounds are checked on their own: no
pair whose bounding circles meet in the window (what ``time_of_impact`` searches) is
ever left out, at any scale, offset, speed and acceleration.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from catalogue import shapes as star_shapes
from catalogue import translated
from hypothesis import assume, given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact import ImpactStatus, InvalidShapeError, Motion, Shape
from polycontact.broad_phase import intervals_array
from polycontact.impacts import (candidate_pairs, event_time, first_impact, first_impacts,
                                 swept_boxes, time_of_impact_many, time_order)

SQ = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
SQ_RINGS = np.array([[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]] * 2)
STATUS_CODES = {ImpactStatus.NO_HIT: 0, ImpactStatus.HIT: 1,
                ImpactStatus.PENETRATING_AT_START: 2, ImpactStatus.OUT_OF_ITERATIONS: 3}
#: A small budget keeps long slides short in the property tests; both sides use it.
BUDGET = 20_000


def agree(x, y) -> bool:
    """Two answers to one pair agree: the same status and state, and the times within
    the time tolerance. The batch runs the pairwise kernel compiled inside its own loop;
    the machine code can round differently in a last place, and one last bit can take a
    search down another, equally valid path (seen after a tolerance change: times
    8e-13 apart under a tolerance of 1e-4). Most answers are equal bit for bit."""
    if x == y:
        return True
    tol = max(x.time_tolerance, y.time_tolerance)

    def close(u, v):
        return (u is None and v is None) or (u is not None and v is not None
                                             and abs(u - v) <= tol)

    return (x.status is y.status and x.state is y.state and x.collides == y.collides
            and close(x.time, y.time) and close(x.first_contact, y.first_contact))


def same_events(got: dict, want: dict) -> bool:
    return got.keys() == want.keys() and all(agree(got[k], want[k]) for k in want)


def brute(shapes, motions, t_max, **kw):
    """Every pair that meets, by the pairwise call: {(i, j): Impact}."""
    out = {}
    for i in range(len(shapes)):
        for j in range(i + 1, len(shapes)):
            imp = pc.time_of_impact(shapes[i], motions[i], shapes[j], motions[j], t_max=t_max,
                                    **kw)
            if imp.state is not None or imp.status is ImpactStatus.OUT_OF_ITERATIONS:
                out[i, j] = imp
    return out


# -- strategies ------------------------------------------------------------------------
@st.composite
def motions(draw, grid: bool) -> Motion:
    """Axis-aligned integer velocities on the grid (exact grazes and flush hits), or
    any velocity, acceleration and spin."""
    if grid:
        axis = draw(st.sampled_from([(1, 0), (0, 1), (1, 1), (0, 0)]))
        speed = draw(st.integers(-4, 4))
        return Motion(velocity=(axis[0] * speed, axis[1] * speed))
    f = st.floats(-8, 8)
    return Motion(velocity=(draw(f), draw(f)),
                  acceleration=draw(st.sampled_from([(0.0, 0.0), (draw(f), draw(f))])),
                  angular_velocity=draw(st.floats(-3, 3)),
                  angular_acceleration=draw(st.sampled_from([0.0, draw(st.floats(-2, 2))])))


@st.composite
def scenes(draw, n_max: int = 5):
    """2..n_max concave bodies (some with holes) in slots along a row, on the integer grid
    or not: apart, touching (a vertex placed on another's vertex), penetrating at the
    start, or aimed at another body (where it will be at a chosen time, give or take
    their radii: hits, grazes and near misses)."""
    grid = draw(st.booleans())
    n = draw(st.integers(2, n_max))
    t_max = float(draw(st.sampled_from([0.0, 0.5, 1.0, 2.0, 3.0]) if grid else st.floats(0, 3)))
    bodies, moves = [], []
    for _ in range(n):
        s = draw(star_shapes(grid=grid, n_max=8))
        m = draw(motions(grid))
        how = draw(st.sampled_from(["random", "aim", "aim", "aim", "vertex", "overlap"]))
        if how != "random" and bodies:
            k = draw(st.integers(0, len(bodies) - 1))
            other, mo = bodies[k], moves[k]
            if how == "vertex":
                va = other.loops[0][draw(st.integers(0, len(other.loops[0]) - 1))]
                vb = s.loops[0][draw(st.integers(0, len(s.loops[0]) - 1))]
                d = va - vb
            elif how == "overlap":
                d = other.centroid - s.centroid + np.round(draw(st.floats(-2, 2)))
            else:
                tau = t_max * draw(st.floats(0, 1))
                reach = other.bounding_radius + s.bounding_radius
                off = reach * draw(st.floats(0.7, 1.3)) * np.array(
                    [math.cos(draw(st.floats(0, 6.3))), math.sin(draw(st.floats(0, 6.3)))])
                d = other.centroid + mo.pose(tau)[0] - m.pose(tau)[0] + off - s.centroid
                if grid:
                    d = np.round(d)
        else:   # spread out along a row of slots 25 apart, with some play
            d = np.array([25.0 * len(bodies), 0.0]) + (
                np.array(draw(st.lists(st.integers(-8, 8), min_size=2, max_size=2)), float)
                if grid else np.array(draw(st.lists(st.floats(-8, 8), min_size=2, max_size=2))))
        bodies.append(translated(s, d))
        moves.append(m)
    return bodies, moves, t_max


# -- time_of_impact_many ----------------------------------------------------------------
@examples(60)
@given(scenes(n_max=4), st.sampled_from(["exact", "sampled"]))
def test_time_of_impact_many_equals_time_of_impact_per_pair(scene, method):
    bodies, moves, t_max = scene
    idx = [(i, j) for i in range(len(bodies)) for j in range(len(bodies)) if i != j]
    a = [bodies[i] for i, _ in idx]
    b = [bodies[j] for _, j in idx]
    ma = [moves[i] for i, _ in idx]
    mb = [moves[j] for _, j in idx]
    batch = time_of_impact_many(a, ma, b, mb, t_max=t_max, method=method,
                                max_iterations=BUDGET)
    assert len(batch) == len(idx)
    for k in range(len(idx)):
        want = pc.time_of_impact(a[k], ma[k], b[k], mb[k], t_max=t_max, method=method,
                                 max_iterations=BUDGET)
        got = batch.impact(k)
        assert agree(got, want)
        if got == want:
            assert got.features == want.features
        assert STATUS_CODES[want.status] == int(batch.statuses[k])
        assert bool(batch.collides[k]) == want.collides
        assert (math.isnan(batch.times[k]) if got.time is None
                else batch.times[k] == got.time)
        assert (math.isnan(batch.first_contacts[k]) if got.first_contact is None
                else batch.first_contacts[k] == got.first_contact)


def test_time_of_impact_many_threads_give_the_same_answers():
    rng = np.random.default_rng(3)
    a = [SQ.moved(rng.uniform(-3, 3, 2), rng.uniform(0, 6)) for _ in range(300)]
    ma = [Motion(velocity=rng.uniform(-2, 2, 2), angular_velocity=rng.uniform(-2, 2))
          for _ in a]
    b = [SQ] * len(a)
    mb = [Motion()] * len(a)
    one = time_of_impact_many(a, ma, b, mb, t_max=2, threads=1)
    two = time_of_impact_many(a, ma, b, mb, t_max=2, threads=2)
    assert one.statuses.tolist() == two.statuses.tolist() and one.collides.any()
    assert list(one) == list(two)
    assert np.array_equal(one.times, two.times, equal_nan=True)


def test_time_of_impact_many_empty_and_arrays_untouched():
    empty = time_of_impact_many([], [], [], [], t_max=1)
    assert len(empty) == 0 and empty.times.shape == (0,)
    ring = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    other = ring + [3.0, 0.0]
    keep = ring.copy(), other.copy()
    batch = time_of_impact_many([ring], [Motion(velocity=(1, 0))], [other], [Motion()], t_max=5)
    assert batch.collides.tolist() == [True]
    assert np.array_equal(ring, keep[0]) and np.array_equal(other, keep[1])


@pytest.mark.parametrize("call, error, message", [
    (lambda: time_of_impact_many([SQ], [Motion()], [SQ, SQ], [Motion()] * 2, t_max=1),
     ValueError, r"shapes_a and shapes_b differ in length \(1 and 2\)"),
    (lambda: time_of_impact_many([SQ, SQ], [Motion(), (1, 0)], [SQ, SQ], [Motion()] * 2,
                                 t_max=1),
     TypeError, r"motions_a\[1\]: expected a polycontact.Motion, got tuple"),
    (lambda: time_of_impact_many([SQ] * 3, [Motion()] * 3, [SQ] * 3, [Motion()] * 2, t_max=1),
     ValueError, r"motions_b: expected 3 motions \(one per shape of shapes_b\), got 2"),
    (lambda: time_of_impact_many([SQ] * 3, [Motion()] * 3, [SQ, SQ, [(0, 0), (1, 1)]],
                                 [Motion()] * 3, t_max=1),
     InvalidShapeError, r"shapes_b\[2\]: .*fewer than 3"),
    (lambda: time_of_impact_many([SQ, SQ.to_shapely().buffer(-0.6)], [Motion()] * 2, [SQ] * 2,
                                 [Motion()] * 2, t_max=1),
     InvalidShapeError, r"shapes_a\[1\]: "),
    (lambda: time_of_impact_many("abc", [], [], [], t_max=1),
     TypeError, "shapes_a: expected a sequence, got str"),
    (lambda: time_of_impact_many([SQ], Motion(), [SQ], [Motion()], t_max=1),
     TypeError, "motions_a: expected a sequence, got Motion"),
    (lambda: time_of_impact_many([SQ], [Motion()], [SQ], [Motion()], t_max=-1),
     ValueError, "t_max"),
    (lambda: time_of_impact_many([SQ], [Motion()], [SQ], [Motion()], t_max=1,
                                 time_tolerance=0), ValueError, "time_tolerance"),
    (lambda: time_of_impact_many([SQ], [Motion()], [SQ], [Motion()], t_max=1, method="fast"),
     ValueError, "method: expected one of exact, sampled"),
    (lambda: time_of_impact_many([SQ], [Motion()], [SQ], [Motion()], t_max=1, threads=0),
     ValueError, "threads: expected an integer >= 1"),
    (lambda: time_of_impact_many([SQ], [Motion()], [SQ], [Motion()], t_max=1, samples=1),
     ValueError, "samples"),
    (lambda: first_impacts([SQ, SQ, SQ], [Motion()] * 2, t_max=1),
     ValueError, r"motions: expected 3 motions \(one per shape of shapes\), got 2"),
    (lambda: first_impacts([SQ, 3], [Motion()] * 2, t_max=1), TypeError,
     r"shapes\[1\]: expected a shape \(.*\), got int"),
    (lambda: first_impacts([SQ, "x"], [Motion()] * 2, t_max=1), ValueError,
     r"shapes\[1\]: "),  # text is WKT (as_shape): a wrong value, not type
    (lambda: first_impacts([SQ, SQ], [Motion(), None], t_max=1), TypeError, r"motions\[1\]: "),
    (lambda: first_impacts([SQ, SQ], [Motion()] * 2, t_max=math.nan), ValueError, "t_max"),
    (lambda: time_of_impact_many([SQ], [Motion()], [SQ], [Motion()], t_max=1).impact(1),
     IndexError, r"k: expected a pair index in \[0, 1\), got 1"),
])
def test_bad_arguments_are_named_with_their_index(call, error, message):
    with pytest.raises(error, match=message):
        call()


# -- time_of_impact_many of ring arrays ---------------------------------------------------
@st.composite
def ring_batches(draw):
    """P pairs of random star-shaped rings of N vertices as two (P, N, 2) arrays (either
    orientation, closed or not, at one scale and offset from the origin), ring b of each
    pair near ring a (hits, grazes, misses, overlaps at the start), and the motions as
    (P, 6) rows: velocities towards each other or not, spins, some accelerations."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    p = draw(st.integers(1, 4))
    n = draw(st.integers(3, 9))
    scale = draw(st.sampled_from([1e-6, 1e-3, 1.0, 1e3, 1e6]))
    offset = draw(st.sampled_from([0.0, 0.0, 1e3, -1e5, 1e9])) * scale
    t_max = draw(st.sampled_from([0.5, 1.0, 3.0]))

    def rings(centres):
        gaps = rng.uniform(0.3, 1.0, (p, n))
        t = np.cumsum(gaps, axis=1) / gaps.sum(axis=1, keepdims=True) * 2 * np.pi
        r = rng.uniform(0.3, 1.0, (p, n))
        xy = np.stack([r * np.cos(t), r * np.sin(t)], axis=2) + centres[:, None, :]
        return xy * scale + offset

    ca = rng.uniform(-1, 1, (p, 2))
    cb = ca + rng.uniform(-3, 3, (p, 2))
    a, b = rings(ca), rings(cb)
    if draw(st.booleans()):
        a = a[:, ::-1]  # clockwise
    if draw(st.booleans()):
        b = np.concatenate([b, b[:, :1]], axis=1)  # closed
    ma = np.zeros((p, 6))
    ma[:, :2] = (cb - ca) / t_max * rng.uniform(0, 1.5, (p, 1)) + rng.uniform(-0.5, 0.5, (p, 2))
    ma[:, 4] = rng.uniform(-2, 2, p)
    if draw(st.booleans()):
        ma[:, 2:4] = rng.uniform(-1, 1, (p, 2))
        ma[:, 5] = rng.uniform(-1, 1, p)
    mb = np.zeros((p, 6))
    mb[:, :2] = rng.uniform(-0.5, 0.5, (p, 2))
    ma[:, :4] *= scale
    mb[:, :4] *= scale
    return np.ascontiguousarray(a), ma, np.ascontiguousarray(b), mb, t_max


def row_motion(row):
    return Motion(velocity=row[:2], acceleration=row[2:4], angular_velocity=row[4],
                  angular_acceleration=row[5])


@examples(60)
@given(ring_batches(), st.sampled_from(["exact", "sampled"]))
def test_time_of_impact_many_of_ring_arrays_equals_time_of_impact_of_their_shapes(batch,
                                                                                  method):
    a, ma, b, mb, t_max = batch
    got = time_of_impact_many(a, ma, b, mb, t_max=t_max, method=method,
                              max_iterations=BUDGET)
    for k in range(len(a)):
        want = pc.time_of_impact(Shape(a[k]), row_motion(ma[k]), Shape(b[k]),
                                 row_motion(mb[k]), t_max=t_max, method=method,
                                 max_iterations=BUDGET)
        one = got.impact(k)
        assert agree(one, want)
        assert STATUS_CODES[want.status] == int(got.statuses[k])
        assert (math.isnan(got.times[k]) if one.time is None else got.times[k] == one.time)


@examples(40)
@given(ring_batches(), st.sampled_from(["exact", "sampled"]))
def test_first_impacts_of_a_ring_array_equals_first_impacts_of_its_shapes(batch, method):
    a, ma, b, mb, t_max = batch
    rings = np.concatenate([a, b[:, :a.shape[1]]])  # (b's closing point dropped)
    rows = np.concatenate([ma, mb])
    got = first_impacts(rings, rows, t_max=t_max, method=method, max_iterations=BUDGET)
    want = first_impacts([Shape(r) for r in rings], [row_motion(m) for m in rows],
                         t_max=t_max, method=method, max_iterations=BUDGET)
    assert same_events({(i, j): imp for i, j, imp in got},
                       {(i, j): imp for i, j, imp in want})
    assert candidate_pairs(rings, rows, t_max=t_max).tolist() == candidate_pairs(
        [Shape(r) for r in rings], rows, t_max=t_max).tolist()


def test_time_of_impact_many_of_ring_arrays_neither_changes_nor_keeps_reading_them():
    ring = np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]] * 2)
    other = ring + [[[3.0, 0.0]], [[0.0, 5.0]]]
    keep = ring.copy(), other.copy()
    rows = np.array([[1.0, 0, 0, 0, 0, 0]] * 2)
    batch = time_of_impact_many(ring, rows, other, np.zeros((2, 6)), t_max=5)
    assert np.array_equal(ring, keep[0]) and np.array_equal(other, keep[1])
    ring[:] = 100.0
    other[:] = -100.0
    hit = batch.impact(0)
    assert batch.collides.tolist() == [True, False] and hit.time == batch.times[0]
    assert abs(hit.time - 2.0) <= hit.time_tolerance
    assert hit.point is not None and abs(hit.point[0] - 3.0) <= 1e-3  # where the square was


def test_time_of_impact_many_of_ring_arrays_leaves_uncertain_rings_to_shape():
    """A ring that is valid but not certified as given (two features closer than its
    tolerance: a slit 1e-13 wide) is answered through its Shape, as the others are."""
    slit = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 1.0], [1.5 + 1e-13, 1.0], [1.5 + 1e-13, 0.5],
                     [1.5, 0.5], [1.5, 1.0], [0.0, 1.0]])
    a = np.stack([slit, slit + 10.0])
    b = np.stack([slit + [5.0, 0.0], slit + [0.0, 5.0]])
    rows = np.array([[1.0, 0, 0, 0, 0, 0], [1.0, 0, 0, 0, 0, 0]])
    batch = time_of_impact_many(a, rows, b, np.zeros((2, 6)), t_max=5)
    for k in range(2):
        want = pc.time_of_impact(Shape(a[k]), row_motion(rows[k]), Shape(b[k]), Motion(),
                                 t_max=5)
        assert agree(batch.impact(k), want)
    assert batch.collides.tolist() == [True, False]


@pytest.mark.parametrize("call, error, message", [
    (lambda: time_of_impact_many(np.zeros((2, 4, 2)), np.zeros((2, 6)),
                                 np.zeros((2, 4, 2)), np.zeros((2, 6)), t_max=1),
     InvalidShapeError, r"shapes_a\[0\]: "),
    (lambda: time_of_impact_many(SQ_RINGS, np.zeros((2, 6)),
                                 np.stack([SQ_RINGS[0], [(0, 0), (1, 1), (1, 0), (0, 1)]]),
                                 np.zeros((2, 6)), t_max=1),
     InvalidShapeError, r"shapes_b\[1\]: outer loop: self-intersection"),
    (lambda: time_of_impact_many(SQ_RINGS, np.zeros((2, 6)), SQ_RINGS[:1], np.zeros((1, 6)),
                                 t_max=1),
     ValueError, r"shapes_a and shapes_b differ in length \(2 and 1\)"),
    (lambda: time_of_impact_many(SQ_RINGS, np.zeros((2, 6)), SQ_RINGS, np.zeros((3, 6)),
                                 t_max=1),
     ValueError, r"motions_b: expected 2 motions .* shape \(2, 6\)"),
    (lambda: time_of_impact_many(SQ_RINGS, np.zeros((2, 6)), SQ_RINGS,
                                 np.array([[0.0] * 6, [1e60, 0, 0, 0, 0, 0]]), t_max=1e50),
     ValueError, r"motions_b\[1\]: the body's coordinates reach"),
    (lambda: time_of_impact_many(SQ_RINGS * 1e120, np.zeros((2, 6)), SQ_RINGS,
                                 np.zeros((2, 6)), t_max=1),
     InvalidShapeError, r"shapes_a\[0\]: "),
])
def test_bad_ring_arrays_are_named_with_their_index(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_first_impacts_of_a_ring_array_names_the_ring_it_refuses():
    rings = np.stack([SQ_RINGS[0], SQ_RINGS[0] + 3, [(0, 0), (1, 1), (1, 0), (0, 1)]])
    with pytest.raises(InvalidShapeError, match=r"shapes\[2\]: outer loop: self-inter"):
        first_impacts(rings, np.zeros((3, 6)), t_max=1)
    with pytest.raises(ValueError, match=r"motions\[1\]: the body's coordinates reach"):
        first_impacts(rings[:2], np.array([[0.0] * 6, [1e60, 0, 0, 0, 0, 0]]), t_max=1e50)


def test_time_of_impact_many_of_empty_ring_arrays():
    empty = time_of_impact_many(np.zeros((0, 4, 2)), np.zeros((0, 6)), np.zeros((0, 5, 2)),
                                np.zeros((0, 6)), t_max=1)
    assert len(empty) == 0 and empty.times.shape == (0,)


# -- first_impacts ---------------------------------------------------------------------
@examples(60)
@given(scenes(), st.sampled_from(["exact", "exact", "sampled"]))
def test_first_impacts_equals_brute_force_over_all_pairs(scene, method):
    bodies, moves, t_max = scene
    want = brute(bodies, moves, t_max, max_iterations=BUDGET, method=method)
    events = first_impacts(bodies, moves, t_max=t_max, max_iterations=BUDGET, method=method)
    assert same_events({(e.i, e.j): e.impact for e in events}, want)
    keys = [(event_time(e.impact), e.i, e.j) for e in events]
    assert keys == sorted(keys)
    # the arrays say what the records say
    assert events.times.tolist() == [k[0] for k in keys]
    assert events.pairs.tolist() == [[e.i, e.j] for e in events]
    assert [pc.ImpactStatus(("no-hit", "hit", "penetrating-at-start", "out-of-iterations")[c])
            for c in events.statuses.tolist()] == [e.impact.status for e in events]
    if method == "sampled":
        return
    first = first_impact(bodies, moves, t_max=t_max, max_iterations=BUDGET)
    if not want:
        assert first is None
        return
    # Scene.first_impact, the all-pairs loop, picks the same pair and the same impact
    scene_obj = pc.Scene(tuple(pc.SceneBody(str(k), s, m) for k, (s, m) in
                               enumerate(zip(bodies, moves))), t_max)
    i, j, imp = _loop_first(scene_obj)
    assert (first.i, first.j) == (i, j) and agree(first.impact, imp)
    assert scene_obj.first_impact(max_iterations=BUDGET)[:2] == (i, j)


def first_order(imp):
    """The order of the first event: collisions (penetrating at the start, hits,
    searches without a verdict) by time before any touch, touches by time."""
    touch_only = imp.status is pc.ImpactStatus.NO_HIT
    return (math.inf if touch_only else event_time(imp), event_time(imp) if touch_only else 0.0)


def _loop_first(scene_obj):
    """The first event of a scene by the loop of time_of_impact over every pair."""
    results = []
    for i, a in enumerate(scene_obj.bodies):
        for j in range(i + 1, len(scene_obj.bodies)):
            b = scene_obj.bodies[j]
            results.append((i, j, pc.time_of_impact(a.shape, a.motion, b.shape, b.motion,
                                                    t_max=scene_obj.t_max,
                                                    max_iterations=BUDGET)))
    return min(results, key=lambda r: first_order(r[2]))


def test_first_impacts_reports_hits_touches_and_start_overlaps_in_time_order():
    shapes = [SQ, SQ.moved((3, 0)), SQ.moved((1.5, 1)), SQ.moved((0, 30)),
              SQ.moved((0, 30.5)), SQ.moved((10, 10))]
    moves = [Motion(velocity=(1, 0)), Motion(), Motion(), Motion(), Motion(), Motion()]
    events = first_impacts(shapes, moves, t_max=5)
    assert [(e.i, e.j, e.impact.status.value) for e in events] == [
        (3, 4, "penetrating-at-start"), (0, 2, "no-hit"), (0, 1, "hit")]
    assert events[1].impact.state is pc.State.CONTACT
    assert first_impact(shapes, moves, t_max=5)[:2] == (3, 4)
    # without the overlapping pair the hit comes first, although the touch is earlier
    assert first_impact(shapes[:3], moves[:3], t_max=5)[:2] == (0, 1)
    assert first_impact(shapes[:1] + shapes[3:4], moves[:2], t_max=5) is None
    assert first_impacts([SQ], [Motion()], t_max=5) == [] and first_impacts([], [], t_max=5) == []


def test_first_impacts_is_a_read_only_sequence_of_records_with_arrays():
    shapes = [SQ, SQ.moved((3, 0)), SQ.moved((1.5, 1))]
    moves = [Motion(velocity=(1, 0)), Motion(), Motion()]
    events = first_impacts(shapes, moves, t_max=5)
    assert isinstance(events, pc.PairImpacts) and len(events) == 2
    assert events == list(events) == events[:] and events != list(events)[:1]
    assert events[-1] == events[1] and (events[1].i, events[1].j) == (0, 1)
    assert [e.i for e in reversed(events)] == [0, 0]
    for bad in (2, -3, 1.0, True):
        with pytest.raises(IndexError, match="event index"):
            events[bad]
    for array in (events.pairs, events.times, events.statuses):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 0
    again = pickle.loads(pickle.dumps(events))
    assert again == events and again.times.tolist() == events.times.tolist()
    empty = first_impacts([SQ], [Motion()], t_max=5)
    assert not empty and empty.pairs.shape == (0, 2) and list(empty) == []
    # a World numbers them by its ids
    world = pc.World()
    world.add(SQ.moved((50, 50)))
    ids = [world.add(s, motion=m) for s, m in zip(shapes, moves)]
    world.remove(0)
    got = world.first_impacts(t_max=5)
    assert got.pairs.tolist() == [[ids[0], ids[2]], [ids[0], ids[1]]]
    assert [(e.i, e.j) for e in got] == [tuple(p) for p in got.pairs.tolist()]


# -- the swept bounds -------------------------------------------------------------------
@st.composite
def swarms(draw):
    """Bodies whose bounding circles come close to one meeting point at chosen times:
    near misses, exact grazes (centre distance = sum of radii at that time) and
    overlaps, for any size (1e-4..1e4), offset (up to 1e9), speed, acceleration, spin
    and window (long travel: up to 1e4 radii)."""
    scale = 10.0 ** draw(st.integers(-4, 4))
    offset = draw(st.sampled_from([0.0, 1e3, 1e6, 1e9])) * np.array(
        [draw(st.floats(-1, 1)), draw(st.floats(-1, 1))])
    t_max = draw(st.sampled_from([1e-3, 1.0, 10.0, 1e3]))
    n = draw(st.integers(2, 8))
    shapes, moves, centres = [], [], []
    for _ in range(n):
        size = scale * draw(st.floats(0.1, 3))
        shape = SQ.moved((0, 0), draw(st.floats(0, 1.5)))
        ring = (shape.loops[0] - shape.centroid) * size
        speed = scale * draw(st.sampled_from([0.0, 1.0, 100.0, 1e4])) / t_max
        v = speed * np.array([draw(st.floats(-1, 1)), draw(st.floats(-1, 1))])
        acc = 2 * speed / t_max * np.array([draw(st.floats(-1, 1)), draw(st.floats(-1, 1))]) \
            if draw(st.booleans()) else np.zeros(2)
        m = Motion(velocity=v, acceleration=acc, angular_velocity=draw(st.floats(-50, 50)),
                   angular_acceleration=draw(st.floats(-50, 50)))
        tau = draw(st.floats(0, 1)) * t_max
        translation, _ = m.pose(tau)
        # a point near the meeting point, at a distance of 0..2 radii (the circles of
        # two bodies meet there when the distances add up)
        where = offset + scale * draw(st.floats(0, 2)) * np.array(
            [math.cos(draw(st.floats(0, 6.3))), math.sin(draw(st.floats(0, 6.3)))])
        try:
            body = Shape(ring + (where - translation))
        except InvalidShapeError:
            assume(False)
        shapes.append(body)
        moves.append(m)
        centres.append(where)
    return shapes, moves, t_max


@examples(400)
@given(swarms())
def test_swept_bounds_never_drop_a_pair_the_pairwise_call_searches(swarm):
    shapes, moves, t_max = swarm
    found = {tuple(p) for p in candidate_pairs(shapes, moves, t_max=t_max).tolist()}
    for i in range(len(shapes)):
        for j in range(i + 1, len(shapes)):
            if len(intervals_array(shapes[i], moves[i], shapes[j], moves[j], t_max)):
                assert (i, j) in found


@given(st.lists(st.sampled_from([0.0, -0.0, 0.25, 0.5, 1e-300, 3.0, math.inf, math.nan]),
                max_size=40))
def test_time_order_is_a_stable_sort_by_time(times):
    t = np.array(times)
    assert time_order(t).tolist() == np.argsort(t, kind="stable").tolist()


@examples(200)
@given(swarms(), st.floats(0, 1))
def test_swept_boxes_hold_each_bounding_circle_at_every_time(swarm, frac):
    shapes, moves, t_max = swarm
    cent = np.array([s.centroid for s in shapes])
    m = np.array([mo.array for mo in moves])
    rad = np.array([s.bounding_radius for s in shapes])
    boxes, owner = swept_boxes(cent, m, rad, t_max)
    t = frac * t_max
    for k, (s, mo) in enumerate(zip(shapes, moves)):
        translation, _ = mo.pose(t)
        c = s.centroid + translation
        mine = boxes[(owner == k) & (boxes[:, 4] <= t) & (t <= boxes[:, 5])]
        assert len(mine) >= 1
        r = s.bounding_radius
        assert any(b[0] <= c[0] - r and c[0] + r <= b[1] and b[2] <= c[1] - r
                   and c[1] + r <= b[3] for b in mine)


def test_swept_bounds_keep_a_grazing_pass_and_drop_far_pairs():
    # circles of radius sqrt(1/2) each: centre distance sqrt(2) is an exact graze
    r = math.sqrt(0.5)
    a = Shape([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)])
    b = a.moved((5, 2 * r))
    far = a.moved((0, 50))
    pairs = candidate_pairs([a, b, far], [Motion(velocity=(1, 0)), Motion(), Motion()],
                            t_max=10)
    assert pairs.tolist() == [[0, 1]]


def test_swept_bounds_far_from_the_origin_grow_by_the_float_spacing():
    # unit squares at 1e9, 10 apart, at rest: the boxes are grown by the rounding of
    # positions there (~3e-5), as the pairwise broad phase is, not by a fraction of the
    # offset (1e-6 of it made every body within 1e3 a candidate)
    far = [SQ.moved((1e9 + 10.0 * k, -1e9)) for k in range(3)]
    assert candidate_pairs(far, [Motion()] * 3, t_max=1e3).tolist() == []
    # ...and a grazing pass there is kept (circles of radius sqrt(1/2), sqrt(2) apart
    # as a passes b: the pairwise broad phase sees them meet)
    a = Shape([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]).moved((1e9, 1e9))
    pair = [a, a.moved((5, math.sqrt(2)))]
    moves = [Motion(velocity=(1, 0)), Motion()]
    assert len(intervals_array(pair[0], moves[0], pair[1], moves[1], 10.0))
    assert candidate_pairs(pair, moves, t_max=10.0).tolist() == [[0, 1]]


@examples(200)
@given(st.sampled_from([1e3, 1e6, 1e9]), st.floats(-1, 1), st.floats(-1, 1), st.floats(0, 6.3),
       st.floats(0, 1.5), st.sampled_from([1e-2, 1.0, 1e2]), st.floats(0.05, 1.5),
       st.sampled_from([0.0, 1.0, 100.0]), st.floats(0, 6.3), st.sampled_from([1e-3, 1.0, 1e3]))
def test_swept_bounds_keep_pairs_within_the_pairwise_rounding_allowance(
        offset, fx, fy, direction, turn, size, frac, speed, heading, t_max):
    # two bodies travelling together far from the origin, their bounding circles apart
    # by a fraction of the widening the pairwise broad phase gives them for the rounding
    # of positions there (rounding_allowance): it searches the pair whenever that
    # widening covers the gap, so the swept boxes must keep it (boxes grown by the
    # radius alone drop it)
    from polycontact._kernels.broad_phase import rounding_allowance

    a = Shape((SQ.moved((0, 0), turn).loops[0] - SQ.centroid) * size + offset * np.array([fx, fy]))
    b = a.moved((0, 0), 0.7)
    v = speed * size / t_max * np.array([math.cos(heading), math.sin(heading)])
    m = Motion(velocity=v)
    allow = rounding_allowance(a.centroid, m.array, a.centroid, m.array, t_max)
    d = (a.bounding_radius + b.bounding_radius + frac * allow) * np.array(
        [math.cos(direction), math.sin(direction)])
    b = b.moved(a.centroid + d - b.centroid)
    if not len(intervals_array(a, m, b, m, t_max)):
        return          # the rounding of the placement took the pair out of reach
    assert candidate_pairs([a, b], [m, m], t_max=t_max).tolist() == [[0, 1]]


@pytest.mark.parametrize("call, error, message", [
    (lambda: candidate_pairs([SQ, SQ.moved((50, 0))],
                             [Motion(velocity=(1e300, 0), acceleration=(-1e300, 0)), Motion()],
                             t_max=1e10), ValueError, r"motions\[0\]: the body's coordinates reach"),
    (lambda: first_impacts([SQ, SQ.moved((3, 0)), SQ.moved((9, 0))],
                           [Motion(), Motion(), Motion(velocity=(1e60, 0))], t_max=1e50),
     ValueError, r"motions\[2\]: the body's coordinates reach .*overflow"),
    (lambda: time_of_impact_many([SQ, SQ], [Motion()] * 2, [SQ, SQ.moved((3, 0))],
                                 [Motion(), Motion(angular_velocity=1e120)], t_max=1),
     ValueError, r"motions_b\[1\]: the body's (points' speeds|angular speed) reach.*overflow"),
    (lambda: time_of_impact_many([SQ], [Motion(acceleration=(0, 1e30))], [SQ], [Motion()],
                                 t_max=1e50),
     ValueError, r"motions_a\[0\]: .*overflow"),
])
def test_motions_that_overflow_float64_are_refused_naming_the_body(call, error, message):
    # time_of_impact refuses them (check_reach); a pair far apart from the others too,
    # whether or not the swept bounds would search it
    with pytest.raises(error, match=message):
        call()


@pytest.mark.parametrize("scale, offset", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e9), (1e-3, 1e6),
                                           (1e-3, 1e9), (1e6, 1e9)])
def test_first_impacts_equals_brute_force_at_any_scale_and_offset(scale, offset):
    rng = np.random.default_rng(7)
    ring = np.array([(0, 0), (4, 0), (4, 3), (3, 3), (3, 1), (1, 1), (1, 3), (0, 3)], float)
    hole = np.array([(1.5, 0.3), (2.5, 0.3), (2.5, 0.7), (1.5, 0.7)])
    shapes, moves = [], []
    for k in range(8):
        d = np.array([5.0 * (k % 4), 4.0 * (k // 4)]) + rng.uniform(-1, 1, 2)
        shapes.append(Shape((ring + d) * scale + offset, [(hole + d) * scale + offset]))
        moves.append(Motion(velocity=rng.uniform(-3, 3, 2) * scale,
                            acceleration=rng.uniform(-1, 1, 2) * scale,
                            angular_velocity=rng.uniform(-1, 1)))
    want = brute(shapes, moves, 1.5, max_iterations=BUDGET)
    events = first_impacts(shapes, moves, t_max=1.5, max_iterations=BUDGET)
    assert same_events({(e.i, e.j): e.impact for e in events}, want)
    assert any(e.impact.collides for e in events)


# the time-of-impact regression cases, through the batched calls: each
# answer (time, time_tolerance, bracket, features) is the pairwise call's
REGRESSION_CASES = {
    "fast_flush": (SQ, Motion(velocity=(2e6, 0)), SQ.moved((3, 0)), Motion(), 5.0, 1e-4),
    "long_travel": (SQ, Motion(velocity=(1, 0)), SQ.moved((1e9, 0.3)), Motion(), 2e9,
                            1e-4),
    "far_away": (SQ.moved((1e9, 0)), Motion(velocity=(1, 0)), SQ.moved((1e9 + 3, 0)),
                         Motion(), 5.0, 1e-4),
    "large_t_max": (SQ, Motion(velocity=(1, 0), angular_velocity=0.5),
                            SQ.moved((3, 0)), Motion(), 1e13, 1e-4),
    "tiny_time_tolerance": (SQ, Motion(velocity=(1, 0)), SQ.moved((3, 0)), Motion(),
                                    5.0, 1e-300),
    "slow_long_window": (SQ, Motion(velocity=(1e-5, 0)), SQ.moved((3, 0)), Motion(),
                                 1e6, 1e-12),
}


@pytest.mark.parametrize("case", sorted(REGRESSION_CASES))
def test_regression_cases_batched_answers_equal_the_pairwise_ones(case):
    a, ma, b, mb, t_max, tol = REGRESSION_CASES[case]
    want = pc.time_of_impact(a, ma, b, mb, t_max=t_max, time_tolerance=tol)
    back = pc.time_of_impact(b, mb, a, ma, t_max=t_max, time_tolerance=tol)
    assert want.collides and back.collides
    batch = time_of_impact_many([a, b], [ma, mb], [b, a], [mb, ma], t_max=t_max,
                                time_tolerance=tol)
    assert list(batch) == [want, back]
    assert batch.impact(0).time_tolerance == want.time_tolerance
    assert batch.impact(0).features == want.features
    # with a bystander far off the path: the one event is the pair's
    away = SQ.moved((-50, 1e3))
    events = first_impacts([a, b, away], [ma, mb, Motion()], t_max=t_max,
                           time_tolerance=tol)
    assert [(e.i, e.j) for e in events] == [(0, 1)] and agree(events[0].impact, want)
