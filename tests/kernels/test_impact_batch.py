"""Kernels of the batched time of impact, on their own (also run as plain Python in CI)."""

from __future__ import annotations

import numpy as np
import pytest

from polycontact import Shape
from polycontact._kernels.advance import edge_table
from polycontact._kernels.impact import pack_body
from polycontact._kernels.impact_batch import body_tables, pack_rings, pair_bodies, ring_bodies, \
    table_sizes
from polycontact.relation import RING_ARGS


def bodies_of(rings):
    """:func:`ring_bodies` of every ring: ``(used, sign, centroids, radii, extents)``."""
    p = len(rings)
    out = (np.empty(p, np.int64), np.empty(p, np.int8), np.empty((p, 2)), np.empty(p),
           np.empty(p))
    ring_bodies(rings, *RING_ARGS, 0, p, *out)
    return out


def test_pair_bodies_gathers_the_bodies_shapes_and_tolerances_of_each_pair():
    rng = np.random.default_rng(3)
    owner = rng.integers(0, 40, 200).astype(np.int64)       # 200 bodies of 40 shapes
    extents = rng.uniform(0.1, 10.0, 50)                    # (10 shapes in no body)
    pairs = np.sort(rng.integers(0, 200, (500, 2)), axis=1).astype(np.int64)
    oi, oj = owner[pairs[:, 0]], owner[pairs[:, 1]]
    wanted = np.zeros(50, np.bool_)
    wanted[oi] = wanted[oj] = True
    want = [pairs[:, 0], pairs[:, 1], oi, oj, 1e-9 * np.maximum(extents[oi], extents[oj]),
            wanted]
    got = pair_bodies(pairs, owner, extents, 1e-9)
    assert all(np.array_equal(g, w) for g, w in zip(got, want))


def test_table_sizes_give_the_most_vertices_of_the_bodies_that_get_a_table():
    # bodies of 3, 9, 4 and 5 vertices (one loop each but the third: two), the 9-gon
    # left out: its tables take no room, and the widest body with tables has 5
    rows = np.array([0, 3, 12, 16, 21], np.int64)
    st_off = np.array([0, 2, 4, 7, 9], np.int64)
    wanted = np.array([True, False, True, True])
    f_off, i_off, widest = table_sizes(rows, st_off, wanted)
    assert widest == 5
    assert np.diff(f_off).tolist() == [11 * 3 - 1, 0, 11 * 4 - 1, 11 * 5 - 1]
    assert np.diff(i_off).tolist() == [7 * 3 + 2, 0, 7 * 4 + 3, 7 * 5 + 2]


def test_body_tables_are_each_bodys_pack_body_bit_for_bit():
    """The tables built in place, body after body with one scratch (a wide body before
    narrower ones, a body with holes, bodies left out), are the arrays ``pack_body``
    makes for each body alone."""
    rng = np.random.default_rng(5)
    shapes = [Shape(np.c_[np.cos(t), np.sin(t)] * rng.uniform(0.5, 1.0, (len(t), 1)) * 10.0
                    ** rng.uniform(-6, 6) + rng.uniform(-1e3, 1e3, 2))
              for t in (np.sort(rng.uniform(0, 2 * np.pi, n)) for n in (40, 3, 12, 7, 25))]
    shapes.insert(2, Shape([(0, 0), (6, 0), (6, 6), (0, 6)],
                           [[(1, 1), (2, 1), (2, 2), (1, 2)], [(3, 3), (5, 3), (5, 5)]]))
    xy = np.concatenate([s.packed[0] for s in shapes])
    rows = np.r_[0, np.cumsum([len(s.packed[0]) for s in shapes])].astype(np.int64)
    starts = np.concatenate([s.packed[1] for s in shapes]).astype(np.int64)
    st_off = np.r_[0, np.cumsum([len(s.packed[1]) for s in shapes])].astype(np.int64)
    centroids = np.array([s.centroid for s in shapes])
    radii = np.array([s.bounding_radius for s in shapes])
    wanted = np.array([True, True, True, False, True, True])
    f_off, i_off, _ = table_sizes(rows, st_off, wanted)
    floats, ints = np.full(f_off[-1], np.nan), np.full(i_off[-1], -7, np.int64)
    body_tables(xy, rows, starts, st_off, centroids, radii, f_off, i_off, 0, len(shapes),
                floats, ints)
    for u, s in enumerate(shapes):
        if not wanted[u]:
            continue
        r = s.packed[0] - centroids[u]
        f, i = pack_body(r, s.packed[1], centroids[u], radii[u], edge_table(r, s.packed[1]))
        assert np.array_equal(floats[f_off[u]:f_off[u + 1]].view(np.int64), f.view(np.int64))
        assert np.array_equal(ints[i_off[u]:i_off[u + 1]], i)


def test_ring_bodies_measure_and_pack_rings_as_shape_does():
    """Centroid, radius and extent as Shape's (summed in another order: within a few
    float spacings of the ring's size), the vertices packed as Shape stores them (a
    clockwise ring reversed, a repeated closing point dropped)."""
    rng = np.random.default_rng(4)
    gaps = rng.uniform(0.3, 1.0, (40, 7))
    t = np.cumsum(gaps, axis=1) / gaps.sum(axis=1, keepdims=True) * 2 * np.pi
    r = rng.uniform(0.3, 1.0, (40, 7))
    rings = np.stack([r * np.cos(t), r * np.sin(t)], axis=2) * 1e3 + rng.uniform(-1e6, 1e6,
                                                                                (40, 1, 2))
    rings[::2] = rings[::2, ::-1].copy()  # clockwise
    rings[1::4, -1] = rings[1::4, 0]      # closed: 6 vertices used
    used, sign, centroids, radii, extents = bodies_of(rings)
    rows = np.r_[0, np.cumsum(used)].astype(np.int64)
    xy = np.empty((rows[-1], 2))
    pack_rings(rings, used, sign, rows, 0, len(rings), xy)
    for p, ring in enumerate(rings):
        shape = Shape(ring)
        assert used[p] == len(shape.loops[0]) == (6 if p % 4 == 1 else 7)
        assert sign[p] == (-1 if p % 2 == 0 else 1)
        assert np.array_equal(xy[rows[p]:rows[p + 1]], shape.loops[0])
        near = 16 * np.spacing(1e6)
        assert np.abs(centroids[p] - shape.centroid).max() <= near
        assert abs(radii[p] - shape.bounding_radius) <= near
        assert extents[p] == max(np.ptp(ring, axis=0))


@pytest.mark.parametrize("ring", [
    [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)],                # self-intersecting
    [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (0.5, 0.0)],                # no area
    [(0.0, 0.0), (1e120, 0.0), (1e120, 1e120), (0.0, 1e120)],        # beyond the range
])
def test_ring_bodies_leave_rings_not_certified_to_shape(ring):
    assert bodies_of(np.array([ring]))[0].tolist() == [-1]


def test_ring_bodies_leave_a_sliver_whose_float_area_is_not_clear_to_shape():
    """A strip 3e-12 wide along the diagonal of the unit square, 301 vertices a side:
    certified valid, but twice its area (8e-12) is within the rounding of its float sum
    (602 products of up to 1): Shape sums it exactly, so the ring is left to Shape."""
    t = np.linspace(0, 1, 301)
    side = np.c_[t, t]
    ring = np.concatenate([side, (side + 3e-12 * np.array([-1, 1]) / np.sqrt(2))[::-1]])
    assert bodies_of(ring[None])[0].tolist() == [-1]
    assert bodies_of(ring[::3][None])[0].tolist() == [len(ring[::3])]  # 201: clear
