"""A World inside a simulation loop: poses as arrays, the geometry of every contact, and
swept steps, each checked against the pairwise calls (``classify``, ``time_of_impact``)
and Shapely, at scales 1e-9..1e9 and up to 1e7 sizes away from the origin."""

from __future__ import annotations

import math
import pickle
import runpy
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import assume, given
from hypothesis import strategies as st
from profiles import examples
from kernels.test_contact_geometry import offset

import polycontact as pc
import polycontact.world as world_module
from polycontact.limits import CONTACT_RESOLUTION

ROOT = Path(__file__).resolve().parents[2]

# (outer loop as the caller gives it, holes): concave, with holes, clockwise, closed
TEMPLATES = [
    ([(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)], []),                       # L
    ([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)], []),       # U
    ([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (1, 3), (3, 3), (3, 1)]]),       # frame
    ([(0, 0), (0, 1), (1, 1), (1, 0)], []),                                       # cw square
    ([(0, 0), (2, 0), (1, 1), (0, 0)], []),                                       # closed
    ([(math.cos(t) * r, math.sin(t) * r) for t, r in
      zip(np.linspace(0, 2 * math.pi, 10, endpoint=False), [1.5, 0.7] * 5)], []),  # star
]

SCALES = [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6, 1e9]
OFFSETS = [0.0, 1e3, 1e7]  # (in sizes of the bodies)


def body(t: int, scale: float, form: str):
    """Template t scaled, as a Shape or as a raw (N, 2) array (no holes)."""
    outer, holes = TEMPLATES[t]
    ring = np.array(outer, dtype=float) * scale
    if form == "array" and not holes:
        return ring
    return pc.Shape(ring, [np.array(h, dtype=float) * scale for h in holes])


poses = st.lists(st.tuples(st.integers(0, len(TEMPLATES) - 1),
                           offset(0.0, 6.0),
                           offset(0.0, 6.0),
                           st.floats(-math.pi, math.pi),
                           st.sampled_from(["shape", "array"])),
                 min_size=2, max_size=8)
frames = st.tuples(st.sampled_from(SCALES), st.sampled_from(OFFSETS))


def build(spec, scale, shift):
    items = [body(t, scale, form) for t, _, _, _, form in spec]
    pos = np.array([(x, y) for _, x, y, _, _ in spec]) * scale + shift * scale
    ang = np.array([a for *_, a, _ in spec])
    return items, pos, ang


def by_caller(shape: pc.Shape):
    """The coordinates of each vertex, and the end points of each edge, keyed by the
    caller's (loop, index)."""
    vertices, edges = {}, {}
    for loop, xy in enumerate(shape.loops):
        k = shape.input_loop(loop)
        for i in range(len(xy)):
            vertices[(k, shape.input_vertex(loop, i))] = xy[i]
            edges[(k, shape.input_edge(loop, i))] = (xy[i], xy[(i + 1) % len(xy)])
    return vertices, edges


def segment_distance(p, a, b) -> float:
    return float(shapely.LineString([a, b]).distance(shapely.Point(p)))


# -- poses ------------------------------------------------------------------------------
@examples(40)
@given(poses, frames)
def test_add_many_with_poses_equals_add_in_a_loop(spec, frame):
    items, pos, ang = build(spec, *frame)
    many = pc.World()
    ids = many.add_many(items, pos, ang)
    one = pc.World()
    for item, p, a in zip(items, pos, ang):
        one.add(item, p, a)
    for i in ids.tolist():
        assert np.array_equal(many.body(i).shape.packed[0], one.body(i).shape.packed[0])
        assert np.array_equal(many.body(i).position, one.body(i).position)
    a, b = many.contacts(), one.contacts()
    assert a.pairs.tolist() == b.pairs.tolist() and a.states.tolist() == b.states.tolist()
    assert np.array_equal(a.tolerances, b.tolerances)
    assert np.array_equal(many.poses()[0], pos) and np.array_equal(many.poses()[1], ang)


@examples(40)
@given(poses, frames, st.lists(st.tuples(st.lists(st.booleans(), min_size=8, max_size=8),
                                         offset(-1.0, 1.0),
                                         st.floats(-2.0, 2.0)),
                               min_size=1, max_size=4))
def test_set_poses_rounds_equal_move_and_a_fresh_world(spec, frame, rounds):
    scale, shift = frame
    items, pos, ang = build(spec, scale, shift)
    world = pc.World()
    ids = world.add_many(items, pos, ang)
    moved = pc.World()
    moved.add_many(items, pos, ang)
    held = world.contacts()  # a Contacts keeps the rows it saw
    pos, ang = pos.copy(), ang.copy()
    for pick, shift, turn in rounds:
        sel = np.array([k for k in range(len(ids)) if pick[k % 8]], dtype=np.int64)
        pos[sel] += shift * scale
        ang[sel] += turn
        world.set_poses(ids[sel], pos[sel], ang[sel])
        for k in sel.tolist():
            moved.move(int(ids[k]), pos[k], float(ang[k]))
    fresh = pc.World()
    for item, p, a in zip(items, pos, ang):
        fresh.add(item, p, a)
    for w in (moved, fresh):
        for i in ids.tolist():
            assert np.array_equal(world.body(i).shape.packed[0], w.body(i).shape.packed[0])
        a, b = world.contacts(), w.contacts()
        assert a.pairs.tolist() == b.pairs.tolist() and a.states.tolist() == b.states.tolist()
    assert np.array_equal(world.poses(ids)[0], pos)
    assert all(held.shape(i).packed[0].shape == world.body(i).shape.packed[0].shape
               for i in ids.tolist())


def test_poses_follow_the_grid_across_cells_and_a_rebuilt_table():
    ring = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    world = pc.World()
    ids = world.add_many(np.stack([ring] * 300))
    rng = np.random.default_rng(3)
    for spread in (1e3, 1e6, 5.0):  # far cells: the hash table fills and is rebuilt
        pos = rng.uniform(0.0, spread, (300, 2))
        world.set_poses(ids, pos, rng.uniform(-3, 3, 300))
        fresh = pc.World()
        for p, a in zip(*world.poses()):
            fresh.add(ring, p, a)
        assert world.contacts().pairs.tolist() == fresh.contacts().pairs.tolist()


def test_set_poses_keeps_the_angles_when_none_are_given():
    world = pc.World()
    ids = world.add_many([body(0, 1.0, "shape")] * 2, [(0, 0), (5, 0)], [0.5, -0.5])
    world.set_poses(ids, [(1, 1), (6, 1)])
    assert world.poses()[1].tolist() == [0.5, -0.5]
    assert world.poses([1])[0].tolist() == [[6.0, 1.0]]


@pytest.mark.parametrize("call, error, message", [
    (lambda w, i: w.set_poses(i, [(0, np.nan), (1, 1)]), ValueError, r"positions\[0\]"),
    (lambda w, i: w.set_poses(i, [(0, 0), (np.inf, 1)]), ValueError, r"positions\[1\]"),
    (lambda w, i: w.set_poses(i, [(0, 0j), (1, 1)]), TypeError, "positions"),
    (lambda w, i: w.set_poses(i, [("0", 0), (1, 1)]), TypeError, "positions"),
    (lambda w, i: w.set_poses(i, [(True, 0), (1, 1)]), TypeError, "positions"),
    (lambda w, i: w.set_poses(i, [(0, 0)]), ValueError, r"positions: expected an array of "
                                                        r"shape \(2, 2\)"),
    (lambda w, i: w.set_poses(i, [(0, 0), (1, 1)], [0.0, np.nan]), ValueError, r"angles\[1\]"),
    (lambda w, i: w.set_poses(i, [(0, 0), (1, 1)], [0.0, "1"]), TypeError, "angles"),
    (lambda w, i: w.set_poses(i, [(0, 0), (1, 1)], [False, True]), TypeError, "angles"),
    (lambda w, i: w.set_poses([0, 7], [(0, 0), (1, 1)]), KeyError, r"ids\[1\]: no body 7"),
    (lambda w, i: w.set_poses([1, 1], [(0, 0), (1, 1)]), ValueError, r"ids\[1\]: body 1 is "
                                                                     "listed twice"),
    (lambda w, i: w.set_poses([0.5, 1], [(0, 0), (1, 1)]), TypeError, "ids"),
    (lambda w, i: w.set_poses(i, [(1e200, 0), (1, 1)]), ValueError, r"positions\[0\]"),

    (lambda w, i: w.poses([3]), KeyError, r"ids\[0\]: no body 3"),
    (lambda w, i: w.add_many([body(3, 1.0, "shape")], [(0, np.nan)]), ValueError,
     r"positions\[0\]"),
    (lambda w, i: w.add_many([body(3, 1.0, "shape")], [(0, 0)], [1j]), TypeError, "angles"),

    (lambda w, i: w.contacts(margin=-1.0), ValueError, "margin"),
    (lambda w, i: w.contacts(margin=float("nan")), ValueError, "margin"),
    (lambda w, i: w.sweep(1.0, [(0, 0)]), ValueError, "velocities"),
    (lambda w, i: w.sweep(1.0, [(0, 0), (np.nan, 0)]), ValueError, r"velocities\[1\]"),
    (lambda w, i: w.sweep(1.0, [(0, 0), (0, 0)], [0, np.inf]), ValueError,
     r"angular_velocities\[1\]"),
    (lambda w, i: w.sweep(1.0, [(0, 0), (0, 0)], accelerations=[(0, 0), (0, "a")]),
     TypeError, "accelerations"),
    (lambda w, i: w.sweep(-1.0, [(0, 0), (0, 0)]), ValueError, "dt"),
    (lambda w, i: w.sweep(1e60, [(0, 0), (1e60, 0)]), ValueError, r"velocities\[1\]"),
])
def test_bad_poses_and_motions_are_refused_naming_the_argument(call, error, message):
    world = pc.World()
    ids = world.add_many([body(3, 1.0, "shape")] * 2, [(0, 0), (3, 0)])
    before = world.poses()
    with pytest.raises(error, match=message):
        call(world, ids)
    assert all(np.array_equal(a, b) for a, b in zip(world.poses(), before))


def test_poses_that_carry_a_body_beyond_the_range_are_refused():
    """A position within the range whose body reaches beyond it (a body 1e86 across at
    1e100)."""
    big = body(3, 1e86, "shape")
    world = pc.World()
    with pytest.raises(pc.InvalidShapeError, match=r"shapes\[0\] placed at positions\[0\]"):
        world.add_many([big], [(1e100, 0.0)])
    assert len(world) == 0
    ids = world.add_many([big], [(0.0, 0.0)])
    with pytest.raises(pc.InvalidShapeError,
                       match=r"body ids\[0\] placed at positions\[0\]: coordinate"):
        world.set_poses(ids, [(1e100, 0.0)])
    assert world.poses()[0].tolist() == [[0.0, 0.0]]


def test_set_poses_reads_the_callers_arrays_once():
    world = pc.World()
    ids = world.add_many([body(3, 1.0, "shape")] * 2, [(0, 0), (3, 0)])
    pos = np.array([[1.0, 1.0], [4.0, 1.0]])
    world.set_poses(ids, pos)
    pos[:] = 99.0
    assert world.poses()[0].tolist() == [[1.0, 1.0], [4.0, 1.0]]


# -- contact geometry --------------------------------------------------------------------
def check_pair(c: pc.Contacts, k: int, world: pc.World, margin: float) -> None:
    i, j = (int(v) for v in c.pairs[k])
    a, b = world.body(i).shape, world.body(j).shape
    r = pc.classify(a, b)
    tol = r.tolerance
    d, n, p = float(c.distances[k]), c.normals[k], c.points[k]
    assert int(c.states[k]) == {"separate": 0, "contact": 1, "penetrating": 2}[r.state.value]
    assert abs(math.hypot(*n) - 1.0) <= 1e-12
    assert abs(d - r.distance) <= 4 * tol, (d, r.distance)
    side = int(c.vertex_sides[k])
    own, other = (a, b) if side == 0 else (b, a)
    vertex = by_caller(own)[0][tuple(int(v) for v in c.vertices[k])]
    edge = by_caller(other)[1][tuple(int(v) for v in c.edges[k])]
    sa, sb = a.to_shapely(), b.to_shapely()
    inter = shapely.union_all([g for g in shapely.get_parts(sa.intersection(sb))
                               if g.geom_type == "Polygon"])
    size = max(np.ptp(a.packed[0], axis=0).max(), np.ptp(b.packed[0], axis=0).max())
    assert abs(c.overlap_areas[k] - inter.area) <= 1e-9 * size * size + 8 * tol * size
    if c.states[k] == 2:
        # moving a by distance * normal ends the penetration: the bodies touch there
        # (the smallest escape may be a single position, an exact fit, so this is
        # checked there; or a tolerance further, out of the tolerance band of a flush
        # contact, where rounding can read the touch as an overlap)
        assert any(pc.classify(a.moved((d - f * tol) * n), b).state is not
                   pc.State.PENETRATING for f in (0.0, 2.0))
        # the carrying vertex goes onto the carrying edge
        shift = d * n if side == 0 else -d * n
        assert segment_distance(vertex + shift, *edge) <= 8 * tol
        if inter.area > 1e-6 * size * size:
            assert math.dist(c.overlap_centroids[k], (inter.centroid.x, inter.centroid.y)) \
                <= 1e-6 * size
        assert inter.boundary.distance(shapely.Point(p)) <= 8 * tol
    elif c.states[k] == 1:
        assert np.array_equal(n, r.normal), (n, r.normal)
        assert segment_distance(vertex, *edge) <= tol
        assert sa.boundary.distance(shapely.Point(p)) <= tol
        assert sb.boundary.distance(shapely.Point(p)) <= tol
    else:
        assert 0.0 < d <= margin
        # a moved by the gap along the normal touches b
        assert pc.classify(a.moved(d * n), b).state is pc.State.CONTACT
        assert abs(segment_distance(vertex, *edge) - d) <= 4 * tol
        assert abs(sa.distance(shapely.Point(p)) - 0.5 * d) <= 4 * tol
    if c.overlap_areas[k] == 0.0:
        assert np.array_equal(c.overlap_centroids[k], p)


@examples(60)
@given(poses, frames, st.sampled_from([0.0, 0.3, 1.0]))
def test_every_geometry_array_equals_classify_and_shapely(spec, frame, margin):
    items, pos, ang = build(spec, *frame)
    world = pc.World()
    world.add_many(items, pos, ang)
    c = world.contacts(margin=margin * frame[0])
    for k in range(len(c)):
        check_pair(c, k, world, margin * frame[0])


@examples(30)
@given(st.lists(st.tuples(st.integers(0, len(TEMPLATES) - 1), st.integers(0, 8),
                          st.integers(0, 8), st.sampled_from([0.0, math.pi / 2, math.pi])),
                min_size=2, max_size=8), frames)
def test_geometry_of_exact_contacts_on_a_grid(spec, frame):
    """Flush edges, vertices on vertices, identical bodies: contacts by construction."""
    check_grid(spec, frame)


def test_a_vertex_on_vertex_touch_gets_classify_s_normal():
    """A clockwise square's corner on a star's tip: two touches fit (the square's side,
    the star's edge), both end at the shared vertex; World and classify pick the same."""
    check_grid([(3, 0, 3, 0.0), (5, 4, 2, math.pi)], (1000.0, 0.0))


def check_grid(spec, frame):
    """Bodies ``spec`` = (template, x, y, angle) on a grid of half-sizes in ``frame`` =
    (scale, shift): every pair of World.contacts is checked by :func:`check_pair`."""
    scale, shift = frame
    items = [body(t, scale, "shape") for t, *_ in spec]
    world = pc.World()
    for item, (_, x, y, a) in zip(items, spec):
        world.add(item, (scale * (0.5 * x + shift), scale * (0.5 * y + shift)), a)
    c = world.contacts()
    for k in range(len(c)):
        check_pair(c, k, world, 0.0)


@examples(40)
@given(poses, frames, st.floats(0.01, 2.0))
def test_margin_lists_every_pair_within_it_and_no_other(spec, frame, margin):
    items, pos, ang = build(spec, *frame)
    world = pc.World()
    world.add_many(items, pos, ang)
    gap = margin * frame[0]
    got = {tuple(p) for p in world.contacts(margin=gap).pairs.tolist()}
    bodies = world.bodies()
    for x in range(len(bodies)):
        for y in range(x + 1, len(bodies)):
            r = pc.classify(bodies[x].shape, bodies[y].shape)
            if r.state is pc.State.SEPARATE and abs(r.distance - gap) <= 1e-9 * gap:
                continue  # at the margin, to the rounding: either answer
            want = r.state is not pc.State.SEPARATE or r.distance <= gap
            assert ((bodies[x].id, bodies[y].id) in got) == want


@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("shift", [0.0, 1e3, 1e9])
def test_pairs_whose_bounding_circles_nearly_touch_are_classified_as_classify_does(
        scale, shift):
    # regular 16-gons tip to tip along the line of their centres: the gap between the
    # tips is the gap between the bounding circles, set to multiples of the tolerance
    t = 2.0 * np.pi * np.arange(16) / 16
    gon = pc.Shape(np.column_stack((np.cos(t), np.sin(t))) * scale)
    world = pc.World()
    origin = np.array([shift, -shift]) * scale
    probe = world.add(gon, origin)
    placed = world.body(probe).shape
    e = pc.classify(placed, placed.moved((3 * scale, 0))).tolerance
    world.remove(probe)
    factors = [0.0, 0.5, 0.99, 1.01, 2.0, 3.5, 100.0]
    for k, f in enumerate(factors):
        centre = origin + (0.0, 5.0 * scale * k)
        world.add(gon, centre)
        world.add(gon, centre + (2.0 * scale + f * e, 0.0))
    bodies = world.bodies()
    for margin in (0.0, 3.0 * e):
        got = {tuple(p) for p in world.contacts(margin=margin).pairs.tolist()}
        for x in range(0, len(bodies), 2):
            r = pc.classify(bodies[x].shape, bodies[x + 1].shape)
            at_margin = abs(r.distance - margin) <= 1e-9 * margin
            if margin and r.state is pc.State.SEPARATE and at_margin:
                continue  # at the margin, to the rounding: either answer
            want = r.state is not pc.State.SEPARATE or r.distance <= margin
            assert ((bodies[x].id, bodies[x + 1].id) in got) == want


def test_geometry_in_parallel_chunks_equals_one_chunk(monkeypatch):
    rng = np.random.default_rng(4)
    items = [body(int(t), 1.0, "shape") for t in rng.integers(0, len(TEMPLATES), 60)]
    world = pc.World()
    world.add_many(items, rng.uniform(0, 12, (60, 2)), rng.uniform(-3, 3, 60))
    one = world.contacts(margin=0.5)
    monkeypatch.setattr(world_module, "_chunks", lambda count, work=1.0: 3)
    many = world.contacts(margin=0.5)
    assert one.pairs.tolist() == many.pairs.tolist()
    for name in ("distances", "normals", "points", "overlap_areas", "overlap_centroids",
                 "vertex_sides", "vertices", "edges"):
        assert np.array_equal(getattr(one, name), getattr(many, name), equal_nan=True), name


def test_features_of_clockwise_closed_rings_are_in_the_callers_numbering():
    cw = np.array([[0.0, 0.0], [0.0, 2.0], [2.0, 2.0], [2.0, 0.0], [0.0, 0.0]])  # closed
    tri = np.array([[1.9, 1.0], [3.0, 0.5], [3.0, 1.5]])  # vertex 0 inside, 0.1 deep
    world = pc.World()
    world.add_many([cw, tri])
    c = world.contacts()
    # the triangle's vertex 0 goes out through the square's edge x = 2, given as edge 2
    # (from its vertex 2, (2, 2), to its vertex 3, (2, 0))
    assert c.states.tolist() == [2] and np.isclose(c.distances[0], -0.1, rtol=1e-12)
    assert c.vertex_sides.tolist() == [1] and c.vertices.tolist() == [[0, 0]]
    assert c.edges.tolist() == [[0, 2]]
    assert np.allclose(c.normals, [[1.0, 0.0]]) and c.points.tolist() == [[1.9, 1.0]]


def test_a_flat_face_pressed_on_a_wall_has_its_depth_and_overlap():
    """Parallel edges running together: the nearest contact segment's foot decides."""
    wall = pc.Shape([(-5, -1), (5, -1), (5, 0), (-5, 0)])
    block = pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
    world = pc.World()
    world.add(wall)
    world.add(block, position=block.centroid - (0, 0.01))
    c = world.contacts()
    assert c.states.tolist() == [2]
    assert math.isclose(c.distances[0], -0.01, rel_tol=1e-9)
    assert np.allclose(c.normals[0], (0.0, 1.0))
    assert math.isclose(c.overlap_areas[0], 0.02, rel_tol=1e-9)


def test_contacts_keep_their_geometry_after_the_world_moves():
    world = pc.World()
    ids = world.add_many([body(3, 1.0, "shape")] * 2, [(0.5, 0.5), (1.25, 0.5)])
    c = world.contacts()
    world.set_poses(ids, [(0.5, 0.5), (9.0, 9.0)])
    assert c.distances.tolist() == [-0.25] and c.overlap_areas.tolist() == [0.25]
    assert c.relation(0).state is pc.State.PENETRATING


# -- swept steps -------------------------------------------------------------------------
motions = st.lists(st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0),
                             st.floats(-6.0, 6.0), st.floats(-2.0, 2.0)),
                   min_size=8, max_size=8)


def _motion(m, scale):
    vx, vy, om, acc = m
    return pc.Motion(velocity=(vx * scale, vy * scale), angular_velocity=om,
                     acceleration=(0.0, acc * scale), angular_acceleration=-acc)


@examples(30)
@given(poses, frames, motions, st.sampled_from([1.0, 0.1, 4.0]))
def test_sweep_agrees_with_time_of_impact_on_every_pair(spec, frame, moves, dt):
    """Fast and spinning bodies, holes, scales: every pair time_of_impact finds is
    reported, with its status, and its times within the time tolerance."""
    scale, _ = frame
    items, pos, ang = build(spec, *frame)
    world = pc.World()
    ids = world.add_many(items, pos, ang)
    ms = [_motion(moves[k % 8], scale) for k in range(len(ids))]
    tol = 1e-4 * dt
    s = world.sweep(dt, [m.velocity for m in ms], [m.angular_velocity for m in ms],
                    [m.acceleration for m in ms], [m.angular_acceleration for m in ms])
    got = {tuple(p): k for k, p in enumerate(s.pairs.tolist())}
    bodies = world.bodies()
    for x in range(len(bodies)):
        for y in range(x + 1, len(bodies)):
            imp = pc.time_of_impact(bodies[x].shape, ms[x], bodies[y].shape, ms[y],
                                    t_max=dt, time_tolerance=tol)
            met = imp.state is not None or imp.status is not pc.ImpactStatus.NO_HIT
            key = (bodies[x].id, bodies[y].id)
            assert (key in got) == met, (key, imp.status, imp.first_contact)
            if not met:
                continue
            k = got[key]
            code = {"no-hit": 0, "hit": 1, "penetrating-at-start": 2,
                    "out-of-iterations": 3}[imp.status.value]
            assert s.statuses[k] == code
            assert s.states[k] == (2 if code in (1, 2) else 1)
            if code == 1:
                assert abs(s.penetration_times[k] - imp.time) <= 2 * imp.time_tolerance
                assert s.times[k] <= s.penetration_times[k]
            if code == 2:
                assert s.times[k] == 0.0 and s.penetration_times[k] == 0.0
            assert abs(math.hypot(*s.normals[k]) - 1.0) <= 1e-9


@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("shift", [0.0, 1e9])
@pytest.mark.parametrize("turn", [False, True])
def test_a_pair_that_ends_the_step_within_the_contact_resolution_is_reported(scale, shift,
                                                                          turn):
    """Two squares whose gap along the line of their centres closes to a third of the
    contact resolution at the end of the step, by a slide or by an eighth of a turn that
    brings a corner round: the sweep reports the touch as time_of_impact does (the line
    of the centres proves nothing within the tolerances)."""
    h = scale
    square = [(-h, -h), (h, -h), (h, h), (-h, h)]
    gap = CONTACT_RESOLUTION * 2.0 * math.sqrt(2.0) * h / 3.0
    if turn:
        x, v, w = h + math.sqrt(2.0) * h + gap, 0.0, math.pi / 4.0
    else:
        x, v, w = 2.0 * h + 0.5 * h + gap, -0.5 * h, 0.0
    origin = np.array([shift * scale, 0.0])
    world = pc.World()
    world.add_many([square, square], [origin, origin + (x, 0.0)], [0.0, 0.0])
    s = world.sweep(1.0, [(0.0, 0.0), (v, 0.0)], [0.0, w])
    bodies = world.bodies()
    imp = pc.time_of_impact(bodies[0].shape, pc.Motion(), bodies[1].shape,
                            pc.Motion(velocity=(v, 0.0), angular_velocity=w), t_max=1.0)
    assert imp.first_contact is not None
    assert s.pairs.tolist() == [[0, 1]]
    assert s.states[0] == (2 if imp.status is pc.ImpactStatus.HIT else 1)


def test_sweep_finds_a_thin_spinning_body_that_passes_through_another():
    """A needle turning half a turn within the step sweeps a disk: the bar it crosses
    and leaves before the step ends is found."""
    needle = pc.Shape([(-2.0, -0.01), (2.0, -0.01), (2.0, 0.01), (-2.0, 0.01)])
    post = pc.Shape([(1.0, 1.0), (1.2, 1.0), (1.2, 1.2), (1.0, 1.2)])
    world = pc.World()
    world.add(needle)
    world.add(post)
    assert len(world.contacts()) == 0
    s = world.sweep(1.0, [(0, 0), (0, 0)], [math.pi, 0.0])
    assert s.pairs.tolist() == [[0, 1]] and s.states.tolist() == [2]
    assert 0.0 < s.times[0] < 0.5
    world.set_poses([0], [(0.0, 0.0)], [math.pi])
    assert len(world.contacts()) == 0  # apart again at the end of the step


def test_sweep_does_not_move_the_bodies_and_reports_contacts_at_the_start():
    world = pc.World()
    ids = world.add_many([body(3, 1.0, "shape")] * 3, [(0.5, 0.5), (1.5, 0.5), (1.0, 0.8)])
    before = world.poses()
    s = world.sweep(0.5, np.zeros((3, 2)))
    assert all(np.array_equal(a, b) for a, b in zip(world.poses(), before))
    assert s.pairs.tolist() == world.contacts().pairs.tolist()
    assert (s.times == 0.0).all()
    assert s.states.tolist() == world.contacts().states.tolist()


def test_a_sweeps_points_are_of_the_step_it_swept_whatever_the_world_did_after(monkeypatch):
    """Read after other sweeps, and after the World moved, removed and added bodies, a
    sweep's points and normals are those read at once, the pair that the compiled depth
    leaves to classify (two interlocking 48-gon gears) included."""
    t = np.arange(48) * 2 * np.pi / 48
    r = np.where(np.arange(48) % 2 == 0, 1.0, 0.8)
    gear = np.c_[r * np.cos(t), r * np.sin(t)]
    world = pc.World()
    ids = world.add_many([gear, gear, body(0, 0.5, "shape")],
                         [(0.0, 0.0), (1.7, 0.05), (5.0, 0.0)], [0.0, 0.1, 0.0])
    vel, spin = np.array([[0.5, 0.0], [-0.5, 0.0], [-3.0, 0.0]]), np.array([0.3, -0.2, 0.0])
    now = world.sweep(1.0, vel, spin)
    want = now.points.copy(), now.normals.copy()
    later = world.sweep(1.0, vel, spin)
    world.set_poses(ids, [(0.2, 0.1), (1.5, 0.0), (5.0, 1.0)], [1.0, 2.0, -1.0])
    kept = [world.sweep(1.0, -vel, -spin) for _ in range(2)]
    for _ in range(3):
        world.sweep(0.5, vel, -spin)
    world.set_poses(ids[1:], [(40.0, 3.0), (-7.0, 9.0)], [2.0, -1.0])
    world.remove(int(ids[0]))
    world.add_many([gear] * 3, [(0.0, 0.0), (1.0, 0.0), (9.0, 9.0)])
    classified = []
    by_shapes = world_module._event_by_shapes
    monkeypatch.setattr(world_module, "_event_by_shapes",
                        lambda ev, k: (classified.append(k), by_shapes(ev, k))[1])
    assert later.pairs.tolist() == now.pairs.tolist() and [0, 1] in now.pairs.tolist()
    assert np.array_equal(later.points, want[0]) and np.array_equal(later.normals, want[1])
    assert classified == [now.pairs.tolist().index([0, 1])]
    assert all(np.isfinite(s.points).all() for s in kept)


def test_a_world_pickles_after_a_sweep_and_sweeps_alike():
    world = pc.World()
    world.add_many([body(t, 1.0, "shape") for t in range(4)],
                   [(0.0, 0.0), (1.2, 0.3), (2.5, 0.0), (9.0, 9.0)])
    vel = np.array([[1.0, 0.0], [0.0, 0.0], [-1.0, 0.5], [0.0, 0.0]])
    first = world.sweep(1.0, vel, [0.5, 0.0, -1.0, 0.0])
    again = pickle.loads(pickle.dumps(world))
    second = again.sweep(1.0, vel, [0.5, 0.0, -1.0, 0.0])
    for name in ("pairs", "times", "states", "points", "normals"):
        assert np.array_equal(getattr(first, name), getattr(second, name)), name


def test_sweep_in_parallel_chunks_equals_one_chunk(monkeypatch):
    rng = np.random.default_rng(5)
    items = [body(int(t), 1.0, "shape") for t in rng.integers(0, len(TEMPLATES), 40)]
    world = pc.World()
    world.add_many(items, rng.uniform(0, 14, (40, 2)), rng.uniform(-3, 3, 40))
    vel, spin = rng.normal(0, 2, (40, 2)), rng.normal(0, 2, 40)
    one = world.sweep(0.5, vel, spin)
    monkeypatch.setattr(world_module, "_chunks", lambda count, work=1.0: 3)
    many = world.sweep(0.5, vel, spin)
    for name in ("pairs", "times", "states", "penetration_times", "statuses", "points",
                 "normals"):
        assert np.array_equal(getattr(one, name), getattr(many, name), equal_nan=True), name


# -- the example --------------------------------------------------------------------------
def test_the_dem_example_runs_a_small_hopper(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "argv", ["dem_hopper.py"])
    example = runpy.run_path(str(ROOT / "examples" / "dem_hopper.py"))
    out = tmp_path / "hopper.png"
    got = example["main"](["--bodies", "300", "--steps", "5", "--check-every", "2",
                           "--out", str(out)])
    assert out.stat().st_size > 0
    assert got["checked"] == 3 and got["skipped"] == 0


def test_near_pairs_are_listed_separate_and_drawn_as_neither_contact_nor_penetration():
    world = pc.World()
    world.add_many([body(3, 1.0, "shape")] * 2, [(0.5, 0.5), (1.75, 0.5)])
    c = world.contacts(margin=0.5)
    assert c.states.tolist() == [0] and c.distances.tolist() == [0.25]
    assert c.to_dict()["contacts"][0]["state"] == "separate"
    assert c.plot().get_title() == "2 bodies: 0 contacts, 0 penetrating pairs, 0 outside the " \
                                   "container"
