"""Vertex and edge indices leave the library in the caller's numbering.

Whatever orientation a ring is given in, closed or not, with repeated points or not,
a feature's ``vertex`` indexes the caller's own array, and its ``edge`` k is the segment
from the caller's vertex k to vertex k + 1 (mod the number passed). The checks here use
only the caller's arrays and Shapely, never the stored loops.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import assume, given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _to_edge(p: np.ndarray, ring: np.ndarray, k: int) -> float:
    """Distance from ``p`` to the caller's edge ``k`` of ``ring`` (not a point)."""
    s, e = ring[k], ring[(k + 1) % len(ring)]
    assert np.any(s != e), f"edge {k} is a repeated point: not the caller's edge"
    u = e - s
    t = min(1.0, max(0.0, float(np.dot(p - s, u)) / float(np.dot(u, u))))
    return float(np.hypot(*(s + t * u - p)))


def _check(features, rings: dict, tol: float) -> None:
    """Every feature read in the caller's arrays means what its kind says. ``rings``
    maps "a" and "b" to the caller's outer ring, or to a list of loops (outer, holes)."""
    loops = {k: r if isinstance(r, list) else [r] for k, r in rings.items()}
    polys = {k: shapely.Polygon(ls[0], ls[1:]) for k, ls in loops.items()}
    for f in features:
        own, other = f.body, "b" if f.body == "a" else "a"
        assert 0 <= f.loop < len(loops[own]) and 0 <= f.other_loop < len(loops[other])
        mine, theirs = loops[own][f.loop], loops[other][f.other_loop]
        assert 0 <= f.edge < len(theirs)
        if f.kind == "edges-cross":
            assert 0 <= f.own_edge < len(mine)
            ea = shapely.LineString(mine[[f.own_edge, (f.own_edge + 1) % len(mine)]])
            eb = shapely.LineString(theirs[[f.edge, (f.edge + 1) % len(theirs)]])
            assert ea.distance(eb) <= tol
            continue
        assert 0 <= f.vertex < len(mine)
        p = mine[f.vertex]
        d = _to_edge(p, theirs, f.edge)
        if f.kind == "vertex-on-edge":
            assert d <= tol, (f, d)
        else:  # vertex-inside: inside the other body, and the edge is its nearest
            assert polys[other].contains(shapely.Point(p))
            assert d <= polys[other].boundary.distance(shapely.Point(p)) + tol


# -- the paper's case 2 ----------------------------------------------------------------
def test_paper_case_2_reports_the_files_vertex():
    """The red vertex that meets blue is the file's vertex 17 (the paper's 18, from 1),
    on blue's edge 30 (the paper's 31-32); it was reported as 23, its place in the
    stored (repaired and reversed) loop. Checked with the file's coordinates: the contact
    point, taken back into each body's frame, is that vertex of the file and on that
    edge of the file."""
    data = json.loads((EXAMPLES / "paper-case-2.json").read_text())
    scene = pc.load_scene(EXAMPLES / "paper-case-2.json", repair=True)
    i, j, impact = scene.first_impact()
    assert impact.collides and (scene.bodies[i].name, scene.bodies[j].name) == ("red", "blue")
    files = {b["name"]: np.array(b["vertices"], dtype=float) for b in data["bodies"]}
    (f,) = [f for f in impact.features if f.vertex is not None]
    assert (f.body, f.vertex, f.edge) == ("a", 17, 30)

    def in_frame(body, t):
        shift, angle = body.motion.pose(t)
        c = body.shape.centroid
        cs, sn = math.cos(-angle), math.sin(-angle)
        q = impact.point - shift - c
        return np.array([cs * q[0] - sn * q[1], sn * q[0] + cs * q[1]]) + c

    red = files["red"]
    p = in_frame(scene.bodies[i], impact.time)
    gaps = np.hypot(*(red - p).T)
    # the features hold at a time within the tolerance (1e-4 s) of `time`: the point
    # moved less than 0.05 in that time; the other vertices are metres away
    assert int(np.argmin(gaps)) == f.vertex and gaps[f.vertex] < 0.05
    assert np.sort(gaps)[1] > 1.0
    q = in_frame(scene.bodies[j], impact.time)
    blue = files["blue"]
    dist = [_to_edge(q, blue, k) for k in range(len(blue))]
    assert int(np.argmin(dist)) == f.edge and dist[f.edge] < 0.05


def test_clockwise_closed_ring_with_repeats_keeps_the_callers_numbers():
    cw = np.array([[0, 0], [0, 0], [0, 1], [1, 1], [1, 1], [1, 0], [0, 0]], dtype=float)
    tri = np.array([[1, 0.5], [2, 0], [2, 1]], dtype=float)
    for a in (cw, pc.Shape(cw), shapely.Polygon(cw), cw.tolist()):
        (f,) = pc.classify(a, tri).features
        # B's vertex 0 lies on the segment (1, 1)-(1, 0): the caller's edge 4
        assert (f.body, f.vertex, f.edge) == ("b", 0, 4)
        (f,) = pc.classify(tri, a).features
        assert (f.body, f.vertex, f.edge) == ("a", 0, 4)


def test_map_survives_rigid_motion_and_has_a_public_form():
    cw = [(0, 0), (0, 2), (2, 2), (2, 0), (0, 0)]
    s = pc.Shape(cw, [[(0.5, 0.5), (1.5, 0.5), (1.0, 1.5)]])  # hole given CCW
    moved = s.moved((3.0, 1.0), 0.7).at(pc.Motion(velocity=(1.0, 0.0)), 2.0)
    for shape in (s, moved):
        assert [shape.input_vertex(0, i) for i in range(4)] == [3, 2, 1, 0]
        assert [shape.input_edge(0, i) for i in range(4)] == [2, 1, 0, 3]
        assert [shape.input_vertex(1, i) for i in range(3)] == [2, 1, 0]
        assert [shape.input_edge(1, i) for i in range(3)] == [1, 0, 2]
        assert shape.input_loop(1) == 1
    for bad in (lambda: s.input_vertex(0, 4), lambda: s.input_edge(0, -1),
                lambda: s.input_vertex(2, 0), lambda: s.input_loop(-1)):
        with pytest.raises(IndexError):
            bad()


def test_repair_keeps_the_callers_numbers_where_it_keeps_the_vertices():
    # the paper's red polygon as printed crosses itself near its vertices 87-90; made
    # valid, its loop starts elsewhere, runs the other way and has a new vertex at the
    # crossing (None); the others are the caller's
    data = json.loads((EXAMPLES / "paper-case-2.json").read_text())
    ring = np.array(data["bodies"][0]["vertices"], dtype=float)
    s = pc.Shape(ring, repair=True)
    new = [i for i in range(len(s.exterior)) if s.input_vertex(0, i) is None]
    assert len(new) == 1 and s.input_loop(0) == 0
    for k in range(len(s.loops)):
        loop = s.loops[k]
        for i, p in enumerate(loop):
            v = s.input_vertex(k, i)
            if v is None:
                assert not (ring == p).all(axis=1).any()
            else:
                assert (ring[v] == p).all()
            e = s.input_edge(k, i)
            if e is not None:
                assert max(_to_edge(p, ring, e), _to_edge(loop[(i + 1) % len(loop)], ring, e)) < 1e-12


# -- every entry point, random rings ---------------------------------------------------
@st.composite
def caller_rings(draw, centre=(0.0, 0.0)):
    """A star-shaped ring as a caller might pass it: either orientation, closed or not,
    with some points repeated."""
    n = draw(st.integers(3, 9))
    angles = np.sort(np.array(draw(st.lists(st.floats(0, 2 * np.pi - 1e-3), min_size=n,
                                            max_size=n, unique=True))))
    if np.min(np.diff(np.append(angles, angles[0] + 2 * np.pi))) < 0.05:
        angles = np.linspace(0, 2 * np.pi, n, endpoint=False) + angles[0]
    radii = np.array(draw(st.lists(st.floats(0.4, 1.2), min_size=n, max_size=n)))
    ring = np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1) + centre
    if draw(st.booleans()):
        ring = ring[::-1]
    repeats = draw(st.lists(st.integers(0, n - 1), max_size=3))
    ring = np.repeat(ring, [1 + repeats.count(i) for i in range(n)], axis=0)
    if draw(st.booleans()):
        ring = np.vstack([ring, ring[:1]])
    return np.ascontiguousarray(ring)


@st.composite
def touching_pairs(draw):
    """Two caller rings, B placed so that one of its vertices lies on an edge of A (or
    a little in or out)."""
    a = draw(caller_rings())
    b = draw(caller_rings())
    ka = draw(st.integers(0, len(a) - 1))
    s, e = a[ka], a[(ka + 1) % len(a)]
    t = draw(st.floats(0.2, 0.8))
    target = s + t * (e - s) + draw(st.sampled_from([0.0, 0.0, 0.05, -0.05]))
    kb = draw(st.integers(0, len(b) - 1))
    return a, np.ascontiguousarray(b + (target - b[kb]))


def _valid(*rings: np.ndarray) -> bool:
    try:
        for r in rings:
            pc.Shape(r)
    except pc.InvalidShapeError:
        return False
    return True


@examples(100)
@given(touching_pairs())
def test_classify_features_index_the_callers_arrays(pair):
    a, b = pair
    assume(_valid(a, b))
    for xa, xb, rings in (
        (a, b, {"a": a, "b": b}),
        (pc.Shape(a), pc.Shape(b), {"a": a, "b": b}),
        (a.tolist(), b.tolist(), {"a": a, "b": b}),
    ):
        r = pc.classify(xa, xb)
        _check(r.features, rings, 4 * r.tolerance)
    pa, pb = shapely.Polygon(a), shapely.Polygon(b)
    r = pc.classify(pa, pb)
    _check(r.features, {"a": np.asarray(pa.exterior.coords), "b": np.asarray(pb.exterior.coords)},
           4 * r.tolerance)


@examples(40)
@given(caller_rings(), caller_rings(centre=(4.0, 0.3)))
def test_time_of_impact_features_index_the_callers_arrays(a, b):
    assume(_valid(a, b))
    v = np.array([-1.0, 0.0])
    hit = pc.time_of_impact(a, pc.Motion(), b, pc.Motion(velocity=tuple(v)), t_max=10.0,
                            time_tolerance=1e-9)
    if not hit.collides:
        return
    # the features hold within the time tolerance of `time`: B is placed then
    _check([f for f in hit.features if f.kind == "vertex-on-edge"],
           {"a": a, "b": b + v * hit.time}, 1e-7)
    assert hit.features


@examples(20)
@given(touching_pairs())
def test_cli_json_features_index_the_files_vertices(pair):
    a, b = pair
    assume(_valid(a, b))
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for name, ring in (("a", a), ("b", b)):
            path = Path(tmp) / f"{name}.json"
            path.write_text(json.dumps({"vertices": ring.tolist()}))
            paths.append(str(path))
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            assert main(["classify", *paths, "--json"]) == 0
    rep = json.loads(out.getvalue())
    features = [pc.Feature(f["body"], f["loop"], f["vertex"], f["other_loop"], f["edge"],
                           f["kind"], f.get("own_edge")) for f in rep["features"]]
    assert tuple(features) == pc.classify(a, b).features
    _check(features, {"a": a, "b": b}, 4 * rep["tolerance"])


@examples(60)
@given(caller_rings(), caller_rings(), st.data())
def test_hole_features_index_the_callers_hole(hole, b, data):
    """A body with a hole given in any form; B touches (or crosses) an edge of the hole."""
    hole = hole * 0.5
    outer = np.array([[-2.0, -2.0], [-2.0, 2.0], [2.0, 2.0], [2.0, -2.0]])  # clockwise
    b = b * 0.3
    k = data.draw(st.integers(0, len(hole) - 1))
    s, e = hole[k], hole[(k + 1) % len(hole)]
    assume(np.any(s != e))
    target = s + data.draw(st.floats(0.2, 0.8)) * (e - s)
    b = np.ascontiguousarray(b + (target - b[data.draw(st.integers(0, len(b) - 1))]))
    assume(_valid(b))
    try:
        a = pc.Shape(outer, [hole])
    except pc.InvalidShapeError:
        assume(False)
    for x, y, rings in ((a, b, {"a": [outer, hole], "b": b}),
                        (b, a, {"a": b, "b": [outer, hole]})):
        r = pc.classify(x, y)
        assert r.features
        _check(r.features, rings, 4 * r.tolerance)
