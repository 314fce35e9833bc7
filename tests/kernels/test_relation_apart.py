"""The state kernel's early exit for separate pairs (``relation._apart``) against the full
test it skips (``relation._overlap_state``), near the tolerance boundary.

``_apart`` may answer "separate" only where the full test does: whenever it fires, the
full test must say separate for the same pair and tolerance. The pairs are placed along
the line of their bounding boxes' centres (the line ``_apart`` projects on) at a gap of
about eps, just above it and just below it, at scales 1e-9..1e9 and offsets up to 1e9,
so both the early exit and the fall-through are taken. Also: the state kernel with its
scratch on its stack (``relate_shapes_into``, what ``classify`` calls on Shapes).
"""

from __future__ import annotations

import numpy as np
import pytest
from catalogue import pairs, shapes
from hypothesis import event, given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact import Shape
from polycontact._kernels import packs as kpack
from polycontact._kernels import primitives as kprim
from polycontact._kernels import relation as kr
from polycontact.tolerances import default_tolerance

#: Gaps as multiples of the pair's tolerance: well inside, at and around the boundary.
FACTORS = (0.0, 0.5, 1.0 - 1e-6, 1.0, 1.0 + 1e-12, 1.0 + 1e-9, 1.0 + 1e-6, 1.0 + 1e-3,
           1.0 + 2.0**-40, 1.5, 4.0)


def _states(xa, sa, xb, sb, eps):
    """(``_apart`` fired, ``state_in``, the full test) for one pair and tolerance."""
    na, nb = sa[-1], sb[-1]
    ba, bb = kprim.bbox(xa, na), kprim.bbox(xb, nb)
    scratch = kpack.state_scratch(na + nb)
    fast = kr.state_in(xa, sa, 1.0, xb, sb, 1.0, eps, scratch)
    full = kr._overlap_state(xa, sa, 1.0, xb, sb, 1.0, eps, ba, bb, scratch)
    return bool(kr._apart(xa, na, xb, nb, ba, bb, eps)), fast, full


def _place(xa: np.ndarray, xb: np.ndarray, w: np.ndarray, gap: float) -> np.ndarray:
    """``xb`` moved so that its box centre lies on the line from ``xa``'s box centre along
    ``w`` (unit) and its vertices project onto ``w`` ``gap`` beyond ``xa``'s."""
    ca = 0.5 * (xa.min(0) + xa.max(0))
    cb = 0.5 * (xb.min(0) + xb.max(0))
    t = gap + (xa - ca).dot(w).max() - (xb - cb).dot(w).min()
    return xb - cb + ca + t * w


def _eps_at(xa, xb, w, factor):
    """The pair's default tolerance once placed ``factor`` tolerances apart (the
    tolerance follows the coordinates' magnitude, which follows the placement)."""
    eps = default_tolerance(xa, xb)
    for _ in range(3):
        eps = default_tolerance(xa, _place(xa, xb, w, factor * eps))
    return eps


def _check(xa, sa, xb, sb, eps):
    apart, fast, full = _states(xa, sa, xb, sb, eps)
    if apart:
        assert full == kr.SEPARATE
    assert fast == full
    return apart, full


@examples(300)
@given(shapes(grid=False), shapes(grid=False), st.integers(-9, 9),
       st.sampled_from([(0.0, 0.0), (1e9, 0.0), (-1e9, 1e9), (3e8, -7e8)]),
       st.floats(0.0, 2.0 * np.pi), st.sampled_from(FACTORS))
def test_early_exit_agrees_with_the_full_test_near_the_tolerance(a, b, power, offset, angle,
                                                                  factor):
    w = np.array([np.cos(angle), np.sin(angle)])
    # far from the origin a body must span many float spacings to stay a polygon
    scale = 10.0 ** (power if offset == (0.0, 0.0) else max(power, -4))
    xa = a.packed[0] * scale + np.array(offset)
    xb0 = b.packed[0] * scale + np.array(offset)
    eps = _eps_at(xa, xb0, w, factor)
    xb = _place(xa, xb0, w, factor * eps)
    for e in (eps, eps * (1.0 - 1e-9), eps * (1.0 + 1e-9), 0.0, 2.0 * eps):
        for apart, _ in (_check(xa, a.packed[1], xb, b.packed[1], e),
                         _check(xb, b.packed[1], xa, a.packed[1], e)):
            event("early exit" if apart else "full test")


def _symmetric(rng: np.random.Generator, n: int) -> np.ndarray:
    """A centrally symmetric star of 2 n vertices with vertex (1, 0) farthest along x:
    its box centre is its centre, so two of them placed along the line of their centres
    have their nearest vertices on that line."""
    t = np.sort(rng.uniform(0.15, np.pi - 0.15, n - 1))
    r = rng.uniform(0.3, 0.95, n - 1)
    half = np.r_[[[1.0, 0.0]], np.c_[r * np.cos(t), r * np.sin(t)]]
    return np.r_[half, -half]


def _turned(xy: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return xy @ np.array([[c, s], [-s, c]])


@pytest.mark.parametrize(("power", "offset"), [(p, 0.0) for p in (-9, -3, 0, 4, 9)]
                         + [(p, 1e9) for p in (-3, 0, 4, 9)])
def test_early_exit_fires_above_the_tolerance_and_falls_through_below(power, offset):
    """Vertex to vertex along the line of centres: 4 eps apart the early exit answers
    separate; at 0.5 eps and just below eps it falls through and the full test finds
    the contact (a threshold that forgot eps, or took a fraction of it, would answer
    separate there)."""
    rng = np.random.default_rng(power + 100)
    scale = 10.0**power
    for k in range(20):
        angle = rng.uniform(0.0, 2.0 * np.pi)
        w = np.array([np.cos(angle), np.sin(angle)])
        xa = _turned(_symmetric(rng, 5), angle) * scale + offset
        xb0 = _turned(_symmetric(rng, 4), angle + np.pi) * scale * rng.uniform(0.5, 2.0) \
            + offset
        sa, sb = np.array([0, len(xa)]), np.array([0, len(xb0)])
        # just inside the tolerance: 1e-3 of it is far above the rounding of the
        # coordinates at offset 0, 1e-1 at offset 1e9 (eps is 64 float spacings there)
        near = 1.0 - (0.1 if offset else 1e-3)
        for factor, fires, state in ((4.0, True, kr.SEPARATE), (0.5, False, kr.CONTACT),
                                     (near, False, kr.CONTACT)):
            eps = _eps_at(xa, xb0, w, factor)
            xb = _place(xa, xb0, w, factor * eps)
            assert Shape(xb).n_vertices == len(xb)  # still a valid polygon
            apart, full = _check(xa, sa, xb, sb, eps)
            assert (apart, full) == (fires, state), (k, factor)


def test_early_exit_never_fires_for_a_body_in_a_hole():
    """A body inside a hole of another is apart from it, but no line separates them: the
    early exit must leave it to the full test."""
    frame = Shape([(0, 0), (10, 0), (10, 10), (0, 10)], holes=[[(2, 2), (2, 8), (8, 8), (8, 2)]])
    inner = Shape([(4, 4), (6, 4), (6, 6), (4, 6)])
    for d in ((0.0, 0.0), (1.9, 0.0), (0.0, -1.9)):
        xb = inner.packed[0] + np.array(d)
        eps = default_tolerance(frame.packed[0], xb)
        apart, full = _check(*frame.packed, xb, inner.packed[1], eps)
        assert not apart and full == kr.SEPARATE


@examples(100)
@given(pairs(holes=None, n_max=40))
def test_state_with_stack_scratch_is_the_allocating_state(pair):
    """relate_shapes_into (the shapes' kernel packs, its scratch on the stack, no
    allocation) gives relate_state's answer, also when called again (the stack holds
    the last call's values); a tolerance below 0 is the pair's default, taken from the
    packs."""
    a, b, _ = pair
    eps = default_tolerance(a.packed[0], b.packed[0])
    assert max(a._tolerance, b._tolerance) == eps
    want = kr.relate_state(*a.packed, *b.packed, eps)
    assert kr.relate_shapes_into(a._kernel, b._kernel, eps) == want
    assert kr.relate_shapes_into(a._kernel, b._kernel, eps) == want  # reused
    assert kr.relate_shapes_into(a._kernel, b._kernel, -1.0) == want
    r = pc.classify(a, b)
    assert r.state.value == ("separate", "contact", "penetrating")[want]
    assert r.tolerance == eps


def test_state_of_a_pair_beyond_the_stack_scratch_is_refused_or_separate():
    """A pair of more than STACK_VERTICES vertices gets -1 (classify then calls
    relate_state), never a state computed in a scratch too small; pairs whose boxes are
    apart need no scratch and are separate at once."""
    assert kpack.STACK_FLOATS == kpack.scratch_floats(kpack.STACK_VERTICES)  # the stack's size
    t = np.linspace(0.0, 2.0 * np.pi, kpack.STACK_VERTICES // 2 + 1, endpoint=False)
    big = Shape(np.c_[np.cos(t), np.sin(t)])
    assert kr.relate_shapes_into(big._kernel, big._kernel, 1e-12) == -1
    assert kr.relate_shapes_into(big._kernel, big.moved((3, 0))._kernel, 1e-12) == kr.SEPARATE
    fits = Shape(np.c_[np.cos(t[:-1]), np.sin(t[:-1])])
    assert fits.n_vertices * 2 == kpack.STACK_VERTICES
    assert kr.relate_shapes_into(fits._kernel, fits._kernel, 1e-12) == kr.PENETRATING
    r = pc.classify(big, big)  # the default tolerance on the allocating path
    assert r.state is pc.State.PENETRATING and r.tolerance == big._tolerance


@examples(50)
@given(pairs(holes=None))
def test_kernel_pack_is_the_shape(pair):
    """A shape's kernel pack unpacks to its packed arrays, its bounding box and its
    tolerance term (what relate_shapes_into reads instead of computing them) and ends
    with its centroid, bounding radius and extent; it cannot be written, and its numbers
    are aligned."""
    for shape in pair[:2]:
        xy, starts, box, tol = kpack.unpack_shape(shape._kernel)
        assert np.array_equal(xy, shape.packed[0]) and np.array_equal(starts, shape.packed[1])
        assert box == kprim.bbox(shape.packed[0], shape.n_vertices)
        assert tol == shape._tolerance
        tail = np.frombuffer(shape._kernel, np.float64)[-kpack.PACK_TAIL:]
        assert tail.tolist() == [*shape.centroid.tolist(), shape.bounding_radius,
                                 shape._extent]
        assert type(shape._kernel) is bytes  # immutable by its type
        # the kernel reads float64 and int64 from the bytes' own storage: 8-byte aligned
        assert np.frombuffer(shape._kernel, np.uint8).ctypes.data % 8 == 0
        assert not xy.flags.writeable and not starts.flags.writeable


@examples(20)
@given(st.lists(shapes(holes=None), min_size=1, max_size=12), st.integers(2, 5))
def test_kernel_packs_unpack_in_chunks_as_in_one(items, chunks):
    """Many kernel packs unpacked in parallel chunks: the arrays of one serial pass, each
    shape's coordinates, loop starts and sizes where its offsets say."""
    blob = np.frombuffer(b"".join(s._kernel for s in items), np.float64)
    one = kpack.unpack_shapes(blob, len(items), 1)
    got = kpack.unpack_shapes(blob, len(items), chunks)
    assert all(np.array_equal(x, y) for x, y in zip(one, got))
    xy, rows, starts, st_off, sizes = got
    for k, s in enumerate(items):
        assert np.array_equal(xy[rows[k] : rows[k + 1]], s.packed[0])
        assert np.array_equal(starts[st_off[k] : st_off[k + 1]], s.packed[1])
        assert sizes[k].tolist() == [*s.centroid.tolist(), s.bounding_radius, s._extent]


def test_scratch_views_do_not_overlap():
    size = 13
    buf = np.zeros(kpack.scratch_floats(size))
    box, ids, touch, rays, rord = kpack.state_scratch_views(buf, size)
    assert box.shape == (size + 1, 4) and ids.shape == (size + 1, 4)
    assert rays.shape == (2 * size + 2, 6) and rord.shape == (2 * size + 2,)
    assert touch.shape[0] >= size + 1
    box[:] = 1.0
    rays[:] = 2.0
    ids[:] = 3
    rord[:] = 4
    touch[:] = True
    assert (box == 1.0).all() and (rays == 2.0).all() and (ids == 3).all()
    assert (rord == 4).all() and touch.all()


def test_default_tolerance_of_two_shapes_is_the_larger_term():
    """A small triangle 1e-7 above the top of a 1e6 square: the pair's default tolerance
    is the square's term (1e-6), so they touch; the triangle's own term (1.4e-8, the
    float spacing of its coordinates) would call them apart. Both orders, through the
    kernel's default (-1.0) and through classify."""
    square = Shape([(0, 0), (1e6, 0), (1e6, 1e6), (0, 1e6)])
    tri = Shape([(5e5, 1e6 + 1e-7), (5e5 + 1, 1e6 + 1e-7), (5e5, 1e6 + 1)])
    assert tri._tolerance < 1e-7 < square._tolerance
    for a, b in ((square, tri), (tri, square)):
        assert kr.relate_shapes_into(a._kernel, b._kernel, -1.0) == kr.CONTACT
        assert kr.relate_shapes_into(a._kernel, b._kernel, tri._tolerance) == kr.SEPARATE
        r = pc.classify(a, b)
        assert r.state is pc.State.CONTACT and r.tolerance == square._tolerance
