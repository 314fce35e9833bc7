"""classify: states against Shapely, symmetry, the lean array path, classify_many."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
import shapely.affinity
from catalogue import (
    CASES,
    agrees_with_shapely,
    pairs,
    shapely_state,
    shifted,
    touching_slivers,
    translated,
)
from hypothesis import given, note
from hypothesis import strategies as st
from profiles import examples

from polycontact import Relation, Shape, State, classify, classify_many
from polycontact.tolerances import default_tolerance


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_catalogue_state(case):
    assert shapely_state(case.a, case.b) == case.state  # the catalogue itself is right
    assert classify(case.a, case.b).state.value == case.state
    assert classify(case.b, case.a).state.value == case.state


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
@pytest.mark.parametrize(
    "direction", [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1)]
)
def test_catalogue_shifted_by_1e9_of_size(case, direction):
    # 2**-30 (about 0.93e-9) times the size: the shifted coordinates stay exact, so
    # Shapely decides exactly, and the shift is far above the tolerance (1e-12 relative).
    size = max(np.ptp(case.a.exterior, axis=0).max(), np.ptp(case.b.exterior, axis=0).max())
    moved = shifted(case, *(2.0**-30 * size * np.array(direction, dtype=float)))
    assert classify(moved.a, moved.b).state.value == shapely_state(moved.a, moved.b)


@pytest.mark.parametrize("case", [c for c in CASES if not c.a.holes and not c.b.holes],
                         ids=lambda c: c.name)
def test_arrays_match_shapes(case):
    a, b = case.a.exterior, case.b.exterior
    for aa, bb in ((a, b), (a[::-1].copy(), b), (a, np.vstack([b, b[:1]]))):
        assert classify(aa, bb).state.value == case.state
    poly = classify(case.a.to_shapely(), case.b.to_shapely())
    assert poly.state.value == case.state


def _agrees(a, b, grid):
    r = classify(a, b)
    if grid:  # exact coordinates: Shapely's answer exactly
        return r.state.value == shapely_state(a, b)
    # Off the grid, a vertex snapped onto another may land a rounding error away:
    # Shapely's answer, or contact where it differs only within the tolerance.
    return agrees_with_shapely(a, b, r.state.value, r.tolerance)


@given(pairs())
def test_random_pairs_match_shapely(pair):
    a, b, grid = pair
    assert _agrees(a, b, grid)
    assert classify(a, b).state is classify(b, a).state


@given(pairs(grid=True, holes=True))
def test_random_pairs_with_holes_on_grid_match_shapely(pair):
    a, b, _ = pair
    assert classify(a, b).state.value == shapely_state(a, b)
    assert classify(b, a).state.value == shapely_state(a, b)


@given(pairs())
def test_distance_separate_and_contact(pair):
    a, b, grid = pair
    r = classify(a, b)
    if r.state is State.SEPARATE:
        gap = float(shapely.distance(a.to_shapely(), b.to_shapely()))
        assert r.distance == pytest.approx(gap, rel=1e-9, abs=1e-12)
        assert r.normal is None
        witness = shapely.Point(r.point)  # the midpoint of a closest pair
        assert shapely.distance(witness, a.to_shapely().boundary) == pytest.approx(
            gap / 2, rel=1e-9, abs=1e-12
        )
    elif r.state is State.CONTACT:
        assert r.distance == 0.0
        assert float(shapely.distance(a.to_shapely(), b.to_shapely())) <= 10 * r.tolerance
        assert np.hypot(*r.normal) == pytest.approx(1.0)
    else:
        assert r.distance < 0.0


def _escape_along(a: Shape, b: Shape, directions: np.ndarray, t_max: float) -> np.ndarray:
    """Smallest t with A + t u not overlapping B, per unit direction u (scan + bisection)."""
    pa = a.to_shapely()
    pb = b.to_shapely()

    def overlapping(t):
        moved = [shapely.affinity.translate(pa, *(tt * u)) for tt, u in zip(t, directions)]
        return np.array([shapely.relate(m, pb)[0] == "2" for m in moved])

    steps = np.linspace(0.0, t_max, 41)
    lo = np.zeros(len(directions))
    hi = np.full(len(directions), t_max)
    found = np.zeros(len(directions), dtype=bool)
    for t0, t1 in zip(steps[:-1], steps[1:]):
        free = ~overlapping(np.full(len(directions), t1)) & ~found
        lo[free] = t0
        hi[free] = t1
        found |= free
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        over = overlapping(mid)
        lo = np.where(over, mid, lo)
        hi = np.where(over, hi, mid)
    return hi


@examples(15)
@given(pairs(n_max=7, holes=False))
def test_depth_against_brute_force(pair):
    a, b, _ = pair
    r = classify(a, b)
    if r.state is not State.PENETRATING:
        return
    depth = -r.distance
    # the escape really ends the overlap, and has the reported length
    moved = translated(a, r.escape)
    assert classify(moved, b).state is not State.PENETRATING
    assert np.hypot(*r.escape) == pytest.approx(depth)
    assert r.normal == pytest.approx(-r.escape / depth)
    # no sampled direction escapes sooner; the best sampled one is close
    angles = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    dirs = np.c_[np.cos(angles), np.sin(angles)]
    span = np.ptp(np.vstack([a.exterior, b.exterior]), axis=0).sum()
    ref = _escape_along(a, b, dirs, span).min()
    assert depth <= ref + 1e-7
    assert ref <= 1.1 * depth + 1e-7


def test_depth_of_simple_cases():
    sq = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    r = classify(sq, sq + [1.5, 0.5])
    assert r.distance == pytest.approx(-0.5)
    assert r.escape == pytest.approx([0.0, -1.5]) or r.escape == pytest.approx([-0.5, 0.0])
    assert classify(sq, sq).distance == pytest.approx(-2.0)
    # the jigsaw tab pushed 0.25 into its socket comes out upwards
    case = next(c for c in CASES if c.name == "tab sunk into its socket")
    r = classify(case.a, case.b)
    assert r.distance == pytest.approx(-0.5)
    assert r.normal == pytest.approx([0.0, 1.0])


@given(pairs(holes=False), st.booleans(), st.booleans())
def test_array_path_matches_shape_path(pair, flip_a, close_b):
    a, b, _ = pair
    xa = a.exterior[::-1].copy() if flip_a else a.exterior.copy()
    xb = np.vstack([b.exterior, b.exterior[:1]]) if close_b else b.exterior.copy()
    before = (xa.copy(), xb.copy())
    ra = classify(xa, xb)
    rs = classify(a, b)
    assert ra.state is rs.state
    assert ra.tolerance == rs.tolerance
    # both in the caller's numbering of xa and xb
    assert ra.features == classify(Shape(xa), Shape(xb)).features
    assert ra.distance == pytest.approx(rs.distance)
    np.testing.assert_array_equal(xa, before[0])
    np.testing.assert_array_equal(xb, before[1])


@examples(30)
@given(st.lists(pairs(), min_size=1, max_size=12))
def test_classify_many_matches_classify(many):
    shapes_a = [p[0] for p in many]
    shapes_b = [p[1] for p in many]
    batch = classify_many(shapes_a, shapes_b)
    single = [classify(a, b) for a, b in zip(shapes_a, shapes_b)]
    assert len(batch) == len(many)
    assert [batch.state(i) for i in range(len(batch))] == [r.state for r in single]
    np.testing.assert_allclose(batch.distances, [r.distance for r in single], atol=1e-9)


def test_classify_many_packed_array_and_mixed_inputs():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    a = np.stack([sq, sq[::-1], sq, sq])
    b = np.stack([sq + 2.0, sq + [1.0, 0.0], sq + 0.5, np.vstack([sq[1:], sq[:1]])])
    keep = (a.copy(), b.copy())
    batch = classify_many(a, b)
    assert batch.states.tolist() == [0, 1, 2, 2]
    np.testing.assert_allclose(batch.distances, [np.sqrt(2), 0.0, -0.5, -1.0])
    np.testing.assert_array_equal(a, keep[0])
    np.testing.assert_array_equal(b, keep[1])
    frame = Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]])
    mixed = classify_many(
        [frame, shapely.box(0, 0, 1, 1), [(0, 0), (1, 0), (0, 1)], sq],
        [sq + 1.5, sq + 1, sq, np.vstack([sq, sq[:1]]) + [0.0, 1.0]],
    )
    assert mixed.states.tolist() == [0, 1, 2, 1]


def test_holes_and_raw_duplicates():
    # repeated vertices make the lean path defer to Shape, which cleans them
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert classify(sq, sq + [1.0, 0.0]).state is State.CONTACT
    ints = [[0, 0], [1, 0], [1, 1], [0, 1]]  # integer lists go through Shape too
    assert classify(ints, ints).state is State.PENETRATING


def test_read_only_and_non_contiguous_inputs():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    ro = sq.copy()
    ro.flags.writeable = False
    assert classify(ro, ro + 1).state is State.CONTACT
    fortran = np.asfortranarray(sq)
    assert classify(fortran, sq + 0.5).state is State.PENETRATING


@given(touching_slivers())
def test_nearly_collinear_touches_and_slivers_match_shapely(pair):
    # Edges leaving a touch point 1e-12 .. 1e-6 rad apart, thin slivers: a penetration
    # thicker than the tolerance is penetrating, whatever the angle (a sliver threshold
    # loosened in the kernel fails here).
    a, b = pair
    note(f"A = {[r.tolist() for r in a.loops]}, B = {b.exterior.tolist()}")
    for x, y in ((a, b), (b, a)):
        r = classify(x, y)
        assert agrees_with_shapely(x, y, r.state.value, r.tolerance)
        if not x.holes and not y.holes:
            assert classify(x.exterior, y.exterior).state is r.state


@pytest.mark.parametrize("d", [1e-6, 1e-7, 1e-8, 1e-9, 1e-10])
def test_sliver_tip_into_an_edge_is_penetrating(d):
    # The case: a kite whose lower tip dips d into the unit square's top edge.
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    kite = np.array([(0.5, 2), (0.2, 1), (0.5, 1 - d), (0.8, 1)])
    assert shapely_state(Shape(sq), Shape(kite)) == "penetrating"
    assert classify(sq, kite).state is State.PENETRATING
    assert classify(kite, sq).state is State.PENETRATING
    assert classify(Shape(kite), Shape(sq)).state is State.PENETRATING


def test_small_shapes_keep_resolution():
    # A shift of 1e-9 of the size is seen at every scale: 1e-5 squares 1e-14 apart.
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) * 1e-5
    b = sq + [1e-5 * (1 + 1e-9), 0.0]
    assert classify(sq, b).state is State.SEPARATE
    assert classify(Shape(sq), Shape(b)).state is State.SEPARATE
    assert classify_many(sq[None], b[None]).states.tolist() == [0]
    assert classify_many([Shape(sq)], [Shape(b)]).states.tolist() == [0]
    assert classify(sq, b).tolerance == pytest.approx(1e-17)
    assert classify(sq, sq + [1e-5, 0.0]).state is State.CONTACT


@pytest.mark.parametrize(
    "call, what, given_type",
    [
        (lambda sq: classify(sq, sq, tolerance="1e-3"), "tolerance", "str"),
        (lambda sq: classify(sq, sq, tolerance=1e-3 + 0j), "tolerance", "complex"),
        (lambda sq: classify(sq, sq, tolerance=True), "tolerance", "bool"),
        (lambda sq: classify_many([sq], [sq], tolerance=b"1"), "tolerance", "bytes"),
        (lambda sq: classify(sq.astype(str).tolist(), sq), "a: outer loop: vertex 0",
         "'0.0' \\(str\\)"),
        (lambda sq: classify(sq, sq + 0j), "b: outer loop", "complex128"),
        (lambda sq: classify(sq > 0, sq), "a: outer loop", "bool"),
        (lambda sq: classify_many((sq + 0j)[None], sq[None]), r"shapes_a\[0\]", "complex"),
        (lambda sq: classify_many([sq], [sq > 0]), r"shapes_b\[0\]", "bool"),
        (lambda sq: Shape(sq, [[("1", "1"), ("2", "1"), ("1", "2")]]), "hole 0: vertex 0",
         "'1' \\(str\\)"),
    ],
)
def test_strings_complex_and_bool_are_refused(call, what, given_type):
    sq = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    with pytest.raises(TypeError, match=f"^{what}: .*expected (a )?real numbers?.*{given_type}"):
        call(sq)


def test_integer_arrays_are_still_accepted():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]])
    assert classify(sq, sq + 1).state is State.CONTACT
    assert classify(sq.astype(np.uint8), sq.astype(np.int32)).state is State.PENETRATING
    assert classify_many(sq[None], (sq + 2)[None]).states.tolist() == [0]
    assert classify(sq, sq, tolerance=np.int64(0)).tolerance == 0.0


def test_prebuilt_shapes_path_matches_the_other_paths():
    # classify() on two Shapes takes a fast path (cached tolerance, compiled entry point
    # bound on first use): the same relation as from arrays, with and without a
    # tolerance, on the first call and after it, and for a Shape subclass
    class Sub(Shape):
        __slots__ = ()

    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    big = Shape(sq * 1e9 + 1e9)
    for d, want in (((2.0, 0.0), State.SEPARATE), ((1.0, 0.5), State.CONTACT),
                    ((0.5, 0.5), State.PENETRATING), ((1.0 + 1e-9, 0.0), State.SEPARATE)):
        for _ in range(2):
            a, b = Shape(sq), Shape(sq + d)
            r = classify(a, b)
            assert r.state is want and r.state is classify(sq, sq + d).state
            assert r.tolerance == classify(sq, sq + d).tolerance
            assert r.tolerance == default_tolerance(a.packed[0], b.packed[0])
            assert classify(a, b, tolerance=0.1).state is classify(sq, sq + d, tolerance=0.1).state
            sub = Sub.__new__(Sub)
            sub._set([np.array(sq + d)], ())
            sub._input = b._input
            assert classify(a, sub).state is want
    # the tolerance of a pair is the larger shape's (not each shape's own)
    assert classify(Shape(sq), big).tolerance == default_tolerance(sq, big.packed[0])
    with pytest.raises(ValueError, match="tolerance"):
        classify(Shape(sq), Shape(sq), tolerance=-1.0)


def test_entry_point_falls_back_to_the_dispatcher():
    from polycontact._dispatch import entry_point

    def plain(x):
        return x + 1

    assert entry_point(plain, (1,)) is plain  # no compiled overloads: the callable itself
    # with the Numba this project pins, the compiled code of a kernel is found (not the
    # dispatcher) and gives the dispatcher's answer
    from polycontact._kernels import relation as kr

    a = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    args = (*a.packed, *a.moved((0.5, 0.5)).packed, 1e-12)
    fast = entry_point(kr.relate_state, args)
    assert (fast is not kr.relate_state) == hasattr(kr.relate_state, "overloads")  # JIT on
    assert fast(*args) == kr.relate_state(*args) == 2


def test_batch_gaps_of_separate_pairs_with_holes_and_long_rings():
    # classify_many's distances find the gap of a separate pair by trying every vertex
    # against every edge (small pairs) or by the sorted sweep (long rings): both must
    # see the holes' edges and agree with Shapely
    frame = Shape([(0, 0), (10, 0), (10, 10), (0, 10)], [[(2, 2), (8, 2), (8, 8), (2, 8)]])
    inner = Shape([(3, 3), (6, 3), (6, 5), (3, 5)])               # in the hole, 1 from it
    t = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    disc = np.c_[np.cos(t), np.sin(t)] * 1.5 + [5.0, 5.0]        # 200 vertices, in the hole
    far = np.c_[np.cos(t), np.sin(t)] + [20.0, 3.0]
    pairs = [(frame, inner), (inner, frame), (frame, disc), (disc, frame), (far, frame),
             (far[::-1].copy(), disc), (inner, inner.moved((0.0, 2.5)))]
    batch = classify_many([p[0] for p in pairs], [p[1] for p in pairs])
    assert batch.states.tolist() == [0] * len(pairs)
    want = [shapely.distance(Shape(a).to_shapely() if not isinstance(a, Shape) else
                             a.to_shapely(),
                             Shape(b).to_shapely() if not isinstance(b, Shape) else
                             b.to_shapely()).item() for a, b in pairs]
    np.testing.assert_allclose(batch.distances, want, rtol=1e-12)
    np.testing.assert_allclose(batch.distances, [classify(a, b).distance for a, b in pairs],
                               rtol=1e-12)


def test_prebuilt_shapes_in_threads_and_above_the_scratch():
    # classify on Shapes keeps its scratch on the kernel's stack (the kernel runs without
    # the GIL): threads classifying at once get the answers of one thread; pairs with
    # more vertices than the stack scratch holds take the allocating kernel, with the
    # same answer
    from concurrent.futures import ThreadPoolExecutor

    from polycontact._kernels import packs as kpack

    t = np.linspace(0.0, 2.0 * np.pi, 300, endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t)] * (1.0 + 0.2 * np.sin(7 * t))[:, None]
    big = Shape(ring)
    assert 2 * big.n_vertices > kpack.STACK_VERTICES
    shapes = [Shape(ring[::20] + [0.5 * k, 0.0]) for k in range(8)] + [big, big.moved((1.9, 0))]
    jobs = [(a, b) for a in shapes for b in shapes]
    want = [classify(a.packed[0], b.packed[0]).state for a, b in jobs]
    with ThreadPoolExecutor(4) as pool:
        for _ in range(3):
            got = list(pool.map(lambda ab: classify(*ab).state, jobs))
            assert got == want
    assert {State.SEPARATE, State.PENETRATING} <= set(want)


def test_a_relation_cannot_be_changed():
    """A Relation (slots, no instance dict) is read-only: its decided parts, its lazy
    parts and new attributes alike; a lazy part is computed once and then kept; it
    survives pickling (for process pools) with what it had computed."""
    import pickle

    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    for r in (classify(sq, sq.moved((0.5, 0.25))), classify(sq.packed[0], sq.packed[0] + 0.5)):
        assert r.state is State.PENETRATING
        point = r.point
        assert r.point is point and r.escape is r.escape
        for name in ("state", "tolerance", "distance", "point", "features", "anything"):
            with pytest.raises(AttributeError):
                setattr(r, name, None)
        with pytest.raises(AttributeError):
            del r.state
        assert not hasattr(r, "__dict__")
        assert r.state is State.PENETRATING and r.point is point
        back = pickle.loads(pickle.dumps(r))
        assert (back.state, back.tolerance, back.distance) == (r.state, r.tolerance, r.distance)
        assert back.features == r.features and np.array_equal(back.point, point)
    with pytest.raises(TypeError, match="classify"):
        Relation(State.CONTACT, 1e-12, sq, sq)


def test_first_classification_of_large_shapes_binds_with_their_own_tolerance(monkeypatch):
    # The first call on Shapes too large for the stack scratch binds the allocating
    # kernel by one call with the caller's arguments: with a made-up tolerance of 1.0,
    # every vertex of a 2e6-vertex unit ring touched every edge near it and that call
    # alone took minutes.
    from polycontact import relation as relation_module
    from polycontact._kernels import packs as kpack

    seen = []

    def spy(dispatcher, args):
        seen.append(args[-1])
        return dispatcher

    monkeypatch.setattr(relation_module, "entry_point", spy)
    monkeypatch.setattr(relation_module, "_state_full", relation_module._bind_state_full)
    t = np.linspace(0.0, 2.0 * np.pi, 400, endpoint=False)
    ring = Shape(np.c_[np.cos(t), np.sin(t)])
    square = Shape([(0.9, -0.1), (1.2, -0.1), (1.2, 0.1), (0.9, 0.1)])
    assert ring.n_vertices > kpack.STACK_VERTICES
    assert classify(ring, square, tolerance=1e-10).state is State.PENETRATING
    assert seen == [1e-10]
