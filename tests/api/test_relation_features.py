"""classify: features, witness point, normal, bad input, and inputs left unchanged."""

from __future__ import annotations

import numpy as np
import pytest
from catalogue import BAR_H, BAR_V, BIG, FRAME, UNIT, pairs

from hypothesis import given

from polycontact import Feature, InvalidShapeError, Shape, State, classify, classify_many

SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def test_vertex_on_edge():
    tri = np.array([[0.5, 1.0], [1.0, 2.0], [0.0, 2.0]])
    r = classify(SQ, tri)
    assert r.features == (Feature("b", 0, 0, 0, 2, "vertex-on-edge"),)
    assert r.point.tolist() == [0.5, 1.0]
    assert r.normal.tolist() == [0.0, 1.0]  # A's outward normal at its top edge


def test_vertex_on_vertex_reports_both_edges():
    r = classify(SQ, SQ + 1.0)
    assert set(r.features) == {
        Feature("a", 0, 2, 0, 0, "vertex-on-edge"),
        Feature("a", 0, 2, 0, 3, "vertex-on-edge"),
        Feature("b", 0, 0, 0, 1, "vertex-on-edge"),
        Feature("b", 0, 0, 0, 2, "vertex-on-edge"),
    }
    assert r.state is State.CONTACT


def test_flush_edges_normal_points_from_a_to_b():
    r = classify(SQ, SQ + [1.0, 0.0])
    assert r.normal.tolist() == [1.0, 0.0]
    r = classify(SQ + [1.0, 0.0], SQ)
    assert r.normal.tolist() == [-1.0, 0.0]


def test_edges_cross_only():
    r = classify(BAR_H, BAR_V)
    kinds = [f.kind for f in r.features]
    assert kinds == ["edges-cross"] * 4
    crossings = {(f.own_edge, f.edge) for f in r.features}
    # BAR_H: edge 0 bottom, 2 top; BAR_V: edge 1 right, 3 left
    assert crossings == {(0, 1), (0, 3), (2, 1), (2, 3)}
    assert all(f.body == "a" and f.vertex is None for f in r.features)
    assert r.point.tolist() in ([1.0, 1.0], [2.0, 1.0], [1.0, 2.0], [2.0, 2.0])


def test_vertex_inside_with_nearest_edge():
    inner = Shape([(0.5, 1), (1.5, 1), (1.5, 2), (0.5, 2)])
    r = classify(BIG, inner)
    inside = [f for f in r.features if f.kind == "vertex-inside"]
    assert {(f.body, f.vertex) for f in inside} == {("b", 0), ("b", 1), ("b", 2), ("b", 3)}
    # vertices at x = 0.5 are nearest BIG's left edge (edge 3)
    assert {f.edge for f in inside if f.vertex in (0, 3)} == {3}
    assert r.distance == pytest.approx(-1.5)  # BIG moves right until x = 1.5


def test_features_of_holes_name_the_loop():
    inner = Shape([(1, 1.5), (2, 1.5), (2, 2.5), (1, 2.5)])
    r = classify(FRAME, inner)
    assert r.state is State.CONTACT
    assert {f.loop for f in r.features if f.body == "a"} <= {1}
    assert {f.other_loop for f in r.features if f.body == "b"} == {1}
    # the square touches the hole's left side: from the frame towards the square
    assert r.normal.tolist() == [1.0, 0.0]


def test_separate_point_and_distance():
    r = classify(SQ, SQ + [3.0, 0.0])
    assert r.state is State.SEPARATE
    assert r.distance == 2.0
    assert r.point[0] == 2.0 and 0.0 <= r.point[1] <= 1.0
    assert r.normal is None and r.escape is None
    assert r.features == ()


def test_repr_and_shapes():
    r = classify(SQ, SQ + 0.5)
    assert repr(r) == "Relation(state='penetrating', tolerance=1e-12)"  # 1e-12 × extent 1
    a, b = r.shapes
    assert isinstance(a, Shape) and a.area == 1.0


@given(pairs())
def test_features_consistent_with_state(pair):
    a, b, _ = pair
    r = classify(a, b)
    kinds = {f.kind for f in r.features}
    if r.state is State.SEPARATE:
        assert r.features == ()
    elif r.state is State.CONTACT:
        assert kinds == {"vertex-on-edge"}
    for f in r.features:
        # the features are in the numbering the shapes were built with: map them back
        own, other = (a, b) if f.body == "a" else (b, a)
        assert 0 <= f.loop < len(own.loops) and 0 <= f.other_loop < len(other.loops)
        loop = other.loops[f.other_loop]
        stored = [i for i in range(len(loop)) if other.input_edge(f.other_loop, i) == f.edge]
        assert len(stored) == 1
        if f.kind == "vertex-on-edge":
            p, q = loop[stored[0]], loop[(stored[0] + 1) % len(loop)]
            mine = own.loops[f.loop]
            v = mine[[own.input_vertex(f.loop, i) for i in range(len(mine))].index(f.vertex)]
            t = np.clip(np.dot(v - p, q - p) / np.dot(q - p, q - p), 0, 1)
            assert np.hypot(*(p + t * (q - p) - v)) <= r.tolerance


@pytest.mark.parametrize(
    "bad, message",
    [
        ([[0, 0], [2, 2], [2, 0], [0, 2]], "a: outer loop: self-intersection at (1, 1)"),
        ([[0, 0], [1, 0]], "a: outer loop: fewer than 3 distinct vertices"),
        ([[0, 0], [1, 0], [np.nan, 1]], "a: outer loop: vertex 2 has a non-finite coordinate"),
        ([[0, 0], [1, 0], [2, 0]], "a: outer loop: zero area"),
        (np.zeros((3, 3)), "a: outer loop: expected an array of shape (N, 2)"),
    ],
)
def test_bad_input_is_refused_with_its_reason(bad, message):
    arr = np.asarray(bad, dtype=float)
    with pytest.raises(InvalidShapeError) as err:
        classify(arr, SQ)
    assert str(err.value).startswith(message)
    with pytest.raises(InvalidShapeError, match="^b: "):
        classify(SQ, arr)
    with pytest.raises(InvalidShapeError, match=r"^shapes_b\[1\]: "):
        classify_many([SQ, SQ], [SQ, arr])
    with pytest.raises(InvalidShapeError, match=r"^shapes_a\[1\]: "):
        classify_many([SQ, arr], [SQ, SQ])


@pytest.mark.parametrize("tol", [-1.0, float("nan"), float("inf")])
def test_bad_tolerance(tol):
    with pytest.raises(ValueError, match="tolerance"):
        classify(SQ, SQ, tolerance=tol)


def test_tolerance_is_used():
    assert classify(SQ, SQ + [1.0 + 1e-6, 0.0]).state is State.SEPARATE
    r = classify(SQ, SQ + [1.0 + 1e-6, 0.0], tolerance=1e-5)
    assert r.state is State.CONTACT and r.tolerance == 1e-5


def test_classify_many_refuses_mismatch_and_nonsense():
    with pytest.raises(ValueError, match="differ in length"):
        classify_many([SQ, SQ], [SQ])
    with pytest.raises(TypeError, match="shapes_a: expected a sequence"):
        classify_many(3, [SQ])


def test_inputs_are_not_modified():
    a = SQ[::-1].copy()  # clockwise
    b = np.vstack([SQ, SQ[:1]]) + 0.5  # closed
    keep = (a.copy(), b.copy())
    r = classify(a, b)
    r.features, r.distance, r.point, r.normal
    np.testing.assert_array_equal(a, keep[0])
    np.testing.assert_array_equal(b, keep[1])
    assert UNIT.exterior.flags.writeable is False  # Shapes stay frozen too


def test_classify_many_array_path_names_the_bad_ring():
    bow = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    a = np.stack([SQ, SQ, SQ])
    b = np.stack([SQ, SQ, bow])
    keep = b.copy()
    with pytest.raises(InvalidShapeError, match=r"^shapes_b\[2\]: .*self-intersect"):
        classify_many(a, b)
    np.testing.assert_array_equal(b, keep)
