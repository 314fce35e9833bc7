"""A result depends only on the arguments as they were at the call: a batch whose
distances are computed on first access must not read the caller's buffers then."""

from __future__ import annotations

import numpy as np

import polycontact as pc

SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def test_a_batch_result_depends_only_on_the_arrays_as_they_were_at_the_call():
    a = np.stack([SQ, SQ])
    b = np.stack([SQ + 0.5, SQ + 3.0])          # penetrating, then apart
    batch = pc.classify_many(a, b)
    want = pc.classify_many(a.copy(), b.copy()).distances
    b[0] = SQ + [10.0, 0.0]                     # the caller reuses its buffers
    a[1] = SQ + [3.0, 0.5]
    assert batch.states.tolist() == [2, 0]
    assert np.array_equal(batch.distances, want)
    assert batch.distances[0] == -0.5


def test_relation_details_depend_only_on_the_arrays_as_they_were_at_the_call():
    a, b = SQ.copy(), SQ + [0.75, 0.5]
    r = pc.classify(a, b)
    b += 5.0
    assert r.state is pc.State.PENETRATING and r.distance == -0.25
    assert r.point is not None and r.point.tolist() != [5.75, 5.5]
