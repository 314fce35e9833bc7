"""Kernels of the batched time of impact, on their own (also run as plain Python in CI)."""

from __future__ import annotations

import numpy as np

from polycontact._kernels.impact_batch import pair_bodies, table_sizes


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
