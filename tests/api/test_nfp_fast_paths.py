"""The no-fit polygon's fast paths and their fallbacks give the same answers.

- Two rings without holes go through one kernel call that decomposes them itself
  (``ring_entrance``); shapes with holes, rings too large for ear clipping and sums past
  the memory budget take the cached-pieces path (``entrance_packed``).
- The outline clips each sum edge by the other sums: with a grid of cells covered whole
  by sums from ``_GRID_MIN_SUMS`` sums on, by a scan of the sums' boxes below.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from nfp_reference import reference_region, same_region
from profiles import examples

import polycontact as pc
from polycontact import nfp as nfp_module
from polycontact._kernels import fits as kfit
from polycontact._kernels import minkowski as kmink
from polycontact._kernels import nfp as kn
from polycontact._kernels import outline as kout
from polycontact.limits import (ANGLE_TOLERANCE, EAR_CLIPPING_MAX, HOLE_WIDTH_FACTOR,
                               MAX_CLIP_TESTS, MAX_SUM_VERTICES, RELATIVE_TOLERANCE,
                               ROUNDING_ULPS, SNAP_FACTOR)

@pytest.fixture(autouse=True)
def no_geos_fallback():
    """Every region here is assembled by polycontact's own kernel (the GEOS fallback
    would hide a wrong outline behind a right region)."""
    before = nfp_module.fallback_count()
    yield
    assert nfp_module.fallback_count() == before, "the GEOS fallback built some region"


ARGS = (-1.0, RELATIVE_TOLERANCE, ROUNDING_ULPS, ANGLE_TOLERANCE)
# the candidates' snapping and merging factors of the packed answers
EXACT = (SNAP_FACTOR, HOLE_WIDTH_FACTOR)


def star(n: int, seed: int, centre=(0.0, 0.0), lo=0.6, hi=3.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = 2.0 * np.pi * (np.arange(n) + rng.uniform(0.1, 0.9, n)) / n
    r = rng.uniform(lo, hi, n)
    return np.column_stack((centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)))


@st.composite
def rings(draw):
    """A star-shaped ring (concave in general, convex sometimes), 3 to 20 vertices."""
    n = draw(st.integers(3, 20))
    seed = draw(st.integers(0, 2**32 - 1))
    lo = draw(st.sampled_from([0.6, 2.9]))  # 2.9: nearly a circle, often convex
    return pc.Shape(star(n, seed, (draw(st.floats(-5, 5)), draw(st.floats(-5, 5))), lo))


@examples(100)
@given(rings(), rings(), st.sampled_from([None, "origin", (0.25, -1.5)]))
def test_ring_kernel_is_the_pieces_path_bit_for_bit(a, b, reference):
    a0 = nfp_module._reference(a, reference, b)
    bxy, bst = nfp_module._convex_pieces(b)
    axy, ast = nfp_module._convex_pieces(a)
    want_head, want = kn.entrance_packed(bxy, bst, a0 - axy, ast, *ARGS, *EXACT,
                                         MAX_CLIP_TESTS)
    head, got = kn.ring_entrance(b.packed[0], a.packed[0], a0[0], a0[1], *ARGS, *EXACT,
                                 EAR_CLIPPING_MAX, MAX_SUM_VERTICES, MAX_CLIP_TESTS)
    assert head[0] == 1.0
    assert head == want_head
    np.testing.assert_array_equal(got, want)


@examples(50)
@given(rings(), rings(), st.booleans())
def test_packed_answer_holds_entrance_region_s(a, b, hole):
    # entrance_packed returns entrance_region's five arrays in one (boxing each array
    # costs); unpacked, they are the same bit for bit (rings, starts, stats, candidates)
    if hole:  # a frame around the star: several rings, candidates where A fits
        (x0, y0), (x1, y1) = b.exterior.min(axis=0) - 1.0, b.exterior.max(axis=0) + 1.0
        b = pc.Shape([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], [b.exterior[::-1]])
    bxy, bst = nfp_module._convex_pieces(b)
    axy, ast = nfp_module._convex_pieces(a)
    _check_packed(bxy, bst, a.centroid - axy, ast)


SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]


@pytest.mark.parametrize("b", [
    pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]),  # slot
    pc.Shape([(-1, -1), (2, -1), (2, 2), (-1, 2)], [[(0, 0), (0, 1), (1, 1), (1, 0)]]),
    pc.Shape([(0, 0), (4, 0), (4, 3), (3, 3), (3, 1), (1, 1), (1, 3), (0, 3)]),  # loose slot
], ids=["slot", "socket", "loose slot"])
def test_packed_candidates_are_the_snapped_merged_sorted_ones(b):
    # exact fits and slides: the candidates made exact in the kernel are those of the
    # Python steps they replace (snap, merge_collinear, sort by ends)
    bxy, bst = nfp_module._convex_pieces(b)
    axy, ast = nfp_module._convex_pieces(pc.Shape(SQUARE))
    n_cand = _check_packed(bxy, bst, -axy, ast)
    assert n_cand > 0 or b.exterior.max() == 4


def _check_packed(bxy, bst, r, ast):
    """entrance_packed = entrance_region, its candidates snapped, merged and sorted as
    the Python code did before the kernel took it over; returns the candidates' count."""
    ring_xy, ring_starts, stats, cand, meta = kn.entrance_region(bxy, bst, r, ast, *ARGS,
                                                                 MAX_CLIP_TESTS)
    head, buf = kn.entrance_packed(bxy, bst, r, ast, *ARGS, *EXACT, MAX_CLIP_TESTS)
    ok, eps, status, n_pts, n_rings, n_vertices, n_cand, tests = head
    assert (ok, eps, status, n_pts, tests) == (1.0, *meta.tolist())
    if len(cand):
        cand = _exact_candidates(cand, int(n_pts), *kmink.convex_sums(bxy, bst, r, ast)[:2], eps)
    assert (n_rings, n_vertices, n_cand) == (len(ring_starts) - 1, len(ring_xy), len(cand))
    for g, w in zip(nfp_module._unpack(buf, n_rings, n_vertices),
                    (ring_xy, ring_starts, stats, cand)):
        assert g.dtype == w.dtype
        np.testing.assert_array_equal(g, w)
    return int(n_cand)


def _exact_candidates(cand, n_pts, sums, starts, eps):
    snap_tol, near = (f * eps for f in EXACT)
    pts = kfit.snap(cand[:n_pts, :2], np.zeros((n_pts, 2)), sums, starts, snap_tol)
    segs = cand[n_pts:]
    along = np.repeat(segs[:, 2:] - segs[:, :2], 2, axis=0)
    ends = kfit.snap(segs.reshape(-1, 2), along, sums, starts, snap_tol)
    merged = kfit.merge_collinear(ends.reshape(-1, 4), near)
    merged = merged[np.lexsort(merged.T[::-1])]
    return np.vstack([np.hstack([pts, pts]), merged])


def _count_paths(monkeypatch):
    calls = {"ring": 0, "pieces": 0}
    real_ring, real_pieces = kn.ring_entrance, kn.entrance_packed

    def ring(*args):
        calls["ring"] += 1
        return real_ring(*args)

    def pieces(*args):
        calls["pieces"] += 1
        return real_pieces(*args)

    monkeypatch.setattr(kn, "ring_entrance", ring)
    monkeypatch.setattr(kn, "entrance_packed", pieces)
    return calls


@pytest.mark.parametrize("case", ["rings", "hole", "large ring", "budget"])
def test_each_path_is_taken_and_right(monkeypatch, case):
    a = pc.Shape(star(7, 1))
    b = pc.Shape(star(9, 2, (1.0, 0.5)))
    want_path = {"ring": 1, "pieces": 0}
    if case == "hole":
        b = pc.Shape(star(9, 2, (1.0, 0.5), 2.0), [star(5, 3, (1.0, 0.5), 0.3, 0.5)[::-1]])
        want_path = {"ring": 0, "pieces": 1}
    elif case == "large ring":  # beyond ear clipping: GEOS's pieces
        b = pc.Shape(star(EAR_CLIPPING_MAX + 11, 4, (1.0, 0.5)))
        want_path = {"ring": 1, "pieces": 1}
    elif case == "budget":  # the ring kernel declines, the pieces path refuses
        monkeypatch.setattr(pc.limits, "MAX_SUM_VERTICES", 20)
    calls = _count_paths(monkeypatch)
    if case == "budget":
        with pytest.raises(nfp_module.NfpTooLargeError):
            pc.no_fit_polygon(a, b)
        assert calls == {"ring": 1, "pieces": 0}
        return
    nfp = pc.no_fit_polygon(a, b)
    assert calls == want_path
    ref = reference_region(a.to_shapely(), b.to_shapely(), nfp.reference)
    assert same_region(nfp.region, ref) is None


@pytest.mark.parametrize("n_sums", [24, 300])
def test_outline_with_and_without_the_grid(n_sums):
    # A concave A of 3 pieces around B of n_sums / 3 pieces: below _GRID_MIN_SUMS the
    # edges are clipped by the box scan alone, from it on the grid's covering sums first.
    a = pc.Shape([(0, 0), (3, 0), (3, 1), (2, 1), (2, 0.4), (1, 0.4), (1, 1), (0, 1)])
    b = pc.Shape(star(n_sums // 3 * 2 + 2, 5, (0.5, 0.5), 1.5, 3.0))
    bxy, bst = nfp_module._convex_pieces(b)
    axy, ast = nfp_module._convex_pieces(a)
    k = (len(bst) - 1) * (len(ast) - 1)
    assert (k >= kmink.GRID_MIN_SUMS) == (n_sums >= kmink.GRID_MIN_SUMS)
    nfp = pc.no_fit_polygon(a, b)
    ref = reference_region(a.to_shapely(), b.to_shapely(), nfp.reference)
    assert same_region(nfp.region, ref) is None


@examples(50)
@given(st.integers(1, 5), st.integers(1, 5), st.integers(0, 2**32 - 1))
def test_distance_to_segments_is_shapely_s(n_pts, n_segs, seed):
    # (the kernel that tells which candidate fits lie on a kept slide)
    rng = np.random.default_rng(seed)
    p = rng.uniform(-3, 3, (n_pts, 2))
    segs = rng.uniform(-3, 3, (n_segs, 2, 2))
    want = [min(shapely.distance(shapely.Point(q), shapely.LineString(s)) for s in segs)
            for q in p]
    np.testing.assert_allclose(kfit.distance_to_segments(p, segs), want, rtol=1e-12, atol=1e-15)


def _former_selection(pts, pts_ok, segs, segs_ok, near):
    """The Python steps select_contacts replaced (the former nfp._clean_degenerate)."""
    slides = segs[segs_ok].reshape(-1, 2, 2)
    on_slide = (kfit.distance_to_segments(pts, slides) <= near if len(slides) and len(pts)
                else np.zeros(len(pts), dtype=bool))
    fits = []
    for p, skip, ok_p in zip(pts, on_slide.tolist(), pts_ok):
        if skip or any(np.hypot(*(p - q)) <= near for q in fits):
            continue
        if ok_p:
            fits.append(p)
    out = np.array(fits).reshape(-1, 2)
    return out[np.lexsort((out[:, 1], out[:, 0]))], slides


@examples(100)
@given(st.integers(0, 8), st.integers(0, 4), st.integers(0, 2**32 - 1))
def test_selected_contacts_are_the_former_python_steps_bit_for_bit(n_pts, n_segs, seed):
    # candidates on a small lattice, repeated, moved by less and more than `near`, on
    # slides and at their ends, each verified or not at random
    rng = np.random.default_rng(seed)
    near = 1e-3
    pts = rng.integers(-2, 3, (n_pts, 2)).astype(float)
    pts += rng.choice([0.0, 0.0, 0.4 * near, 3.0 * near], (n_pts, 2))
    segs = np.tile(rng.integers(-2, 3, (n_segs, 2)).astype(float), 2)
    segs[:, 2:] += np.array([(1, 0), (0, 1), (1, 1), (2, -1)])[rng.integers(0, 4, n_segs)]
    if n_pts and n_segs:
        pts[0] = segs[0, :2] + 0.5 * near  # a fit at a slide's end
    pts_ok = rng.random(n_pts) < 0.7
    segs_ok = rng.random(n_segs) < 0.6
    fits, slides = kfit.select_contacts(pts, pts_ok, segs, segs_ok, near)
    want_fits, want_slides = _former_selection(pts, pts_ok, segs, segs_ok, near)
    assert fits.shape == want_fits.shape and slides.shape == want_slides.shape
    np.testing.assert_array_equal(fits, want_fits)
    np.testing.assert_array_equal(slides, want_slides)


@pytest.mark.parametrize("b, fits, slides", [
    (pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]),  # slot
     [], [[[1.0, 1.0], [1.0, 3.0]]]),
    (pc.Shape([(-1, -1), (2, -1), (2, 2), (-1, 2)], [[(0, 0), (0, 1), (1, 1), (1, 0)]]),
     [[0.0, 0.0]], []),  # socket
    (pc.Shape([(0, 0), (4, 0), (4, 3), (3, 3), (3, 1), (1, 1), (1, 3), (0, 3)]),
     [], []),  # loose slot: no candidate survives
], ids=["slot", "socket", "loose slot"])
def test_no_fit_polygon_selects_its_candidates_in_one_kernel_call(monkeypatch, b, fits, slides):
    # the no-fit polygon verifies and selects its candidates in the kernel
    # (touching_contacts); the same selection from the classifier's verdicts taken one
    # by one in Python (the path inner_fit_polygon's Shapely check takes) agrees
    nfp = pc.no_fit_polygon(SQUARE, b, "origin")
    assert nfp.exact_fits.tolist() == fits and nfp.slides.tolist() == slides

    def check(pts, segs):
        def touches(p):
            moved = pc.Shape(SQUARE).moved(p)
            return pc.classify(moved, b, tolerance=16 * nfp.tolerance).state.value == "contact"
        return [touches(p) for p in pts], [
            touches(0.5 * (s[:2] + s[2:])) and touches(s[:2]) and touches(s[2:]) for s in segs]

    calls = []
    monkeypatch.setattr(nfp_module, "_touching", lambda *args: calls.append(1) or (
        nfp_module._checked(check)))
    slow = pc.no_fit_polygon(SQUARE, b, "origin")
    assert len(calls) == (b.exterior.max() != 4 or len(b.holes) > 0)
    np.testing.assert_array_equal(slow.exact_fits, nfp.exact_fits)
    np.testing.assert_array_equal(slow.slides, nfp.slides)


def _former_assembly(segs, tol):
    """The former assemble_rings: every end linked by the clockwise rule
    (_first_clockwise), also where a single start is there."""
    seg = segs[np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]) > tol]
    n = len(seg)
    order = np.argsort(seg[:, 0], kind="stable")
    sx = seg[order, 0]
    nxt = [kout._first_clockwise(seg, order, sx, np.searchsorted(sx, seg[r, 2] - tol), r, tol)
           for r in range(n)]
    assert min(nxt, default=0) >= 0 and len(set(nxt)) == n
    xy, starts, seen = [], [0], set()
    for r0 in range(n):
        r = r0
        while r not in seen:
            seen.add(r)
            xy.append(seg[r, :2])
            r = nxt[r]
        if len(xy) > starts[-1]:
            starts.append(len(xy))
    xy = np.array(xy).reshape(-1, 2)
    return xy, kout._split_pinched(xy, np.array(starts, np.int64), tol)


@examples(60)
@given(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4)), min_size=1, max_size=12,
                unique=True))
def test_rings_are_linked_as_by_the_clockwise_rule_bit_for_bit(cells):
    # unions of lattice squares: rings touching at corners (several starts at a point,
    # where the clockwise rule decides) and plain vertices (one start, taken at once)
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    xy = np.concatenate([sq + c for c in cells])
    starts = np.arange(0, 4 * len(cells) + 1, 4, dtype=np.int64)
    outline, _ = kout.edge_cover(xy, starts, kmink.boxes(xy, starts), kmink.frames(xy, starts),
                               1e-12)
    ok, got_xy, got_starts = kout.assemble_rings(outline, 4e-12)
    assert ok
    want_xy, want_starts = _former_assembly(outline, 4e-12)
    np.testing.assert_array_equal(got_xy, want_xy)
    np.testing.assert_array_equal(got_starts, want_starts)


@st.composite
def lattice_sums(draw):
    """A few convex polygons on a small lattice (squares, triangles, hulls): shared
    corners and edges, where the closed ones surround points on their boundaries."""
    polys = []
    for _ in range(draw(st.integers(1, 6))):
        pts = draw(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3)), min_size=3,
                            max_size=6, unique=True))
        hull = shapely.convex_hull(shapely.MultiPoint(pts))
        if hull.geom_type == "Polygon":
            polys.append(np.asarray(shapely.orient_polygons(hull).exterior.coords)[:-1])
    if not polys:
        polys.append(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    xy = np.concatenate(polys).astype(float)
    starts = np.r_[0, np.cumsum([len(p) for p in polys])].astype(np.int64)
    return xy, starts


DIRECTIONS = [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 2), (0, 0), (0.6, -0.8)]


@examples(100)
@given(lattice_sums(), st.integers(0, 2**32 - 1))
def test_may_be_surrounded_is_false_only_where_not_surrounded(sums, seed):
    # the pre-test of degenerate_contacts' short parts: at the sums' vertices, edge
    # middles and lattice points (shared corners and edges, outline vertices), in
    # every direction (along the edges too), never False where surrounded is True
    xy, starts = sums
    bb, fr = kmink.boxes(xy, starts), kmink.frames(xy, starts)
    eps, ang = 1e-12, ANGLE_TOLERANCE
    rng = np.random.default_rng(seed)
    pts = np.vstack([xy, 0.5 * (xy + np.roll(xy, -1, axis=0)),
                     rng.integers(0, 4, (8, 2)) + rng.choice([0.0, 0.5, 3e-13], (8, 2))])
    rejected = 0
    for px, py in pts:
        around = kfit.surrounded(px, py, starts, bb, fr, eps, ang)
        for vx, vy in DIRECTIONS:
            may = kfit.may_be_surrounded(px, py, vx, vy, starts, bb, fr, eps, ang)
            assert may or not around, (px, py, vx, vy)
            rejected += not may
    assert rejected > 0  # (outline vertices at least: the pre-test does reject)


def test_may_be_surrounded_at_a_corner_of_four_squares_and_of_one():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    xy = np.concatenate([sq, sq + [1, 0], sq + [0, 1], sq + [1, 1]])
    starts = np.arange(0, 17, 4, dtype=np.int64)
    bb, fr = kmink.boxes(xy, starts), kmink.frames(xy, starts)
    args = (starts, bb, fr, 1e-12, ANGLE_TOLERANCE)
    for v in DIRECTIONS:  # the shared corner: every direction is entered
        assert kfit.may_be_surrounded(1.0, 1.0, *v, *args)
    assert kfit.may_be_surrounded(2.0, 1.0, -1.0, 0.0, *args)  # (surrounded says no)
    assert not kfit.may_be_surrounded(2.0, 1.0, 1.0, 0.0, *args)  # outline: out of it
    assert not kfit.may_be_surrounded(2.0, 2.0, 1.0, 1.0, *args)
    assert not kfit.may_be_surrounded(2.0, 2.0, 0.0, 0.0, *args)  # no direction: (1, 0)
