"""Kernels of the batched time of impact, on their own (also run as plain Python in CI)."""

from __future__ import annotations

import numpy as np

from polycontact._kernels.impact_batch import pair_bodies


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
