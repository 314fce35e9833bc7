"""Every index a World returns is in the caller's numbering of the shape as added.

A clockwise ring, or one with a repeated closing point, is stored counter-clockwise
without the repeat; the features of ``contacts().relation(k)`` must still name the
caller's vertices and edges, exactly as :func:`polycontact.classify` of the same two
bodies does.
"""

from __future__ import annotations

import numpy as np
import pytest

import polycontact as pc

# clockwise and closed: vertex 3 is (1, 0), vertex 2 is (1, 1)
CW_CLOSED = [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)]
RIGHT = [(1.0, 0.25), (2.0, 0.25), (2.0, 0.75), (1.0, 0.75)]  # touches its right side


def _features(relation: pc.Relation) -> set[tuple]:
    return {(f.body, f.loop, f.vertex, f.other_loop, f.edge, f.kind) for f in relation.features}


@pytest.mark.parametrize("form", ["list", "array", "shape"])
@pytest.mark.parametrize("how", ["add", "add_many"])
def test_world_features_are_numbered_as_the_caller_gave_the_vertices(form, how):
    ring = {"list": CW_CLOSED, "array": np.array(CW_CLOSED),
            "shape": pc.Shape(CW_CLOSED)}[form]
    other = pc.Shape([(1.0, 1.0), (2.0, 1.0), (2.0, 2.0), (1.0, 2.0)])  # corner on corner
    world = pc.World()
    if how == "add":
        world.add(ring)
        world.add(other)
    else:
        world.add_many([ring, other])
    contacts = world.contacts()
    assert contacts.pairs.tolist() == [[0, 1]]
    want = pc.classify(np.array(CW_CLOSED), other)
    got = contacts.relation(0)
    assert got.state is want.state is pc.State.CONTACT
    assert _features(got) == _features(want)
    assert {f.vertex for f in got.features if f.body == "a"} == {2}  # (1, 1), as passed
    # the record's shapes keep the numbering too
    body = world.body(0)
    assert body.shape.input_vertex(0, 0) == want.shapes[0].input_vertex(0, 0)
    assert contacts.shape(0).input_edge(0, 1) == want.shapes[0].input_edge(0, 1)


def test_moved_and_queried_shapes_keep_the_callers_numbering():
    world = pc.World()
    i = world.add(CW_CLOSED, position=(0.5, 0.5))
    world.move(i, (0.5, 0.5), angle=0.0)
    query = world.query(RIGHT)
    assert query.ids.tolist() == [i]
    placed = world.body(i).shape
    # stored vertex 0 of the counter-clockwise loop is the caller's vertex 3, (1, 0)
    assert placed.exterior[0].tolist() == [1.0, 0.0] and placed.input_vertex(0, 0) == 3
    want = pc.classify(RIGHT, CW_CLOSED)
    got = pc.classify(query.shape, placed)
    assert _features(got) == _features(want)
