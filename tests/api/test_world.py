"""World: every answer equals brute force over all pairs with ``classify``."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
import polycontact.world as world_module
from polycontact.tolerances import default_tolerance

# ../shared/datasets beside the repository (its parent, or the parent of a worktree's
# directory).
DATASETS = next((p / "shared" / "datasets" for p in Path(__file__).resolve().parents[2:5]
                 if (p / "shared" / "datasets").is_dir()), Path("/nonexistent"))

# Concave bodies and bodies with holes, on an integer grid.
TEMPLATES = [
    pc.Shape([(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)]),                  # L
    pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]),  # U
    pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]]),  # frame
    pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)]),                                  # square
    pc.Shape([(0, 0), (2, 0), (1, 1)]),                                          # triangle
]
CONTAINER = pc.Shape([(0, 0), (12, 0), (12, 10), (0, 10)], [[(5, 4), (7, 4), (7, 6), (5, 6)]])

pose = st.tuples(
    st.integers(0, len(TEMPLATES) - 1),
    st.tuples(st.integers(0, 24).map(lambda v: v / 2), st.integers(0, 20).map(lambda v: v / 2)),
    st.sampled_from([0.0, math.pi / 2, math.pi, 0.3, -1.1]),
)
# (op, pose, which): add a body, move one, remove one
ops = st.lists(
    st.tuples(st.sampled_from(["add", "add", "add", "move", "remove"]), pose, st.integers(0, 99)),
    min_size=1, max_size=40,
)


def build(op_list, container=None, scale=1.0, offset=0.0):
    world = pc.World(container)
    for op, (t, p, a), which in op_list:
        ids = world.ids
        pos = np.array(p) * scale + offset
        if op == "add" or not len(ids):
            world.add(TEMPLATES[t] if scale == 1.0 and offset == 0.0 else scaled(t, scale, offset),
                      pos, a)
        elif op == "move":
            world.move(int(ids[which % len(ids)]), pos, a)
        else:
            world.remove(int(ids[which % len(ids)]))
    return world


def scaled(t, scale, offset):
    s = TEMPLATES[t]
    return pc.Shape(s.exterior * scale + offset, [h * scale + offset for h in s.holes])


CODES = {"separate": 0, "contact": 1, "penetrating": 2}


def brute_contacts(world, tolerance=None):
    bodies = world.bodies()
    pairs, states = [], []
    for a, b in itertools.combinations(bodies, 2):
        s = pc.classify(a.shape, b.shape, tolerance=tolerance).state
        code = CODES[s.value]
        if code:
            pairs.append((a.id, b.id))
            states.append(code)
    return pairs, states


def shapely_container_state(shape, container):
    body, c = shape.to_shapely(), container.to_shapely()
    eps = default_tolerance(shape.packed[0], container.packed[0])
    if body.difference(c).area > 1e-9 * body.area:
        return 2
    return 1 if body.distance(c.boundary) <= eps else 0


@examples(100)
@given(ops)
def test_contacts_equal_brute_force(op_list):
    world = build(op_list)
    got = world.contacts()
    pairs, states = brute_contacts(world)
    assert got.pairs.tolist() == [list(p) for p in pairs]
    assert got.states.tolist() == states


@examples(40)
@given(ops, st.sampled_from([(1e-9, 0.0), (1e6, 0.0), (1.0, 1e9), (1e-3, 1e6), (1e6, -1e9)]))
def test_contacts_equal_brute_force_at_any_scale_and_offset(op_list, frame):
    scale, offset = frame
    world = build(op_list, scale=scale, offset=offset)
    pairs, states = brute_contacts(world)
    got = world.contacts()
    assert got.pairs.tolist() == [list(p) for p in pairs]
    assert got.states.tolist() == states


@examples(30)
@given(ops, st.sampled_from([0.0, 1e-3, 0.5]))
def test_contacts_with_a_tolerance_equal_brute_force(op_list, tolerance):
    world = build(op_list)
    got = world.contacts(tolerance=tolerance)
    pairs, states = brute_contacts(world, tolerance)
    assert got.pairs.tolist() == [list(p) for p in pairs]
    assert got.states.tolist() == states


@examples(60)
@given(ops, st.lists(pose, min_size=1, max_size=8))
def test_query_and_query_many_equal_brute_force(op_list, probes):
    world = build(op_list, CONTAINER)
    for t, p, a in probes:
        q = world.query(TEMPLATES[t], p, a)
        expect = {}
        for body in world.bodies():
            s = CODES[pc.classify(q.shape, body.shape).state.value]
            if s:
                expect[body.id] = s
        assert q.ids.tolist() == sorted(expect)
        assert q.states.tolist() == [expect[i] for i in sorted(expect)]
        assert q.container_state == shapely_container_state(q.shape, CONTAINER)
        assert q.fits == (q.container_state < 2 and 2 not in expect.values())
        worst = max([q.container_state, *expect.values()])
        assert world.query_many(TEMPLATES[t], [p], [a]).tolist() == [worst]
    shape = TEMPLATES[probes[0][0]]
    positions = [p for _, p, _ in probes]
    angles = [a for _, _, a in probes]
    many = world.query_many(shape, positions, angles)
    one = [max([world.query(shape, p, a).container_state,
                *world.query(shape, p, a).states.tolist()]) for p, a in zip(positions, angles)]
    assert many.tolist() == one


@examples(60)
@given(ops)
def test_container_states_equal_shapely(op_list):
    world = build(op_list, CONTAINER)
    got = world.contacts()
    expect = {b.id: shapely_container_state(b.shape, CONTAINER) for b in world.bodies()}
    expect = {i: s for i, s in expect.items() if s}
    assert got.container_ids.tolist() == sorted(expect)
    assert got.container_states.tolist() == [expect[i] for i in sorted(expect)]


def test_many_random_concave_bodies_equal_brute_force():
    rng = np.random.default_rng(7)
    world = pc.World()
    for _ in range(300):
        t = int(rng.integers(len(TEMPLATES)))
        world.add(TEMPLATES[t], rng.integers(0, 60, 2) / 2, float(rng.choice([0, np.pi / 2, 0.7])))
    for i in rng.choice(world.ids, 60, replace=False):
        world.move(int(i), rng.integers(0, 60, 2) / 2, 0.0)
    for i in rng.choice(world.ids, 30, replace=False):
        world.remove(int(i))
    got = world.contacts()
    pairs, states = brute_contacts(world)
    assert got.pairs.tolist() == [list(p) for p in pairs]
    assert got.states.tolist() == states
    assert (got.states == 2).any() and (got.states == 1).any()


def test_relation_of_a_contact_is_the_pairwise_relation():
    world = pc.World()
    a = world.add(TEMPLATES[3], (0.5, 0.5))
    b = world.add(TEMPLATES[3], (1.5, 1.0))
    c = world.contacts()
    rel = c.relation(0)
    assert c.pairs.tolist() == [[a, b]] and rel.state == pc.State.CONTACT
    assert rel.features == pc.classify(world.body(a).shape, world.body(b).shape).features
    with pytest.raises(IndexError, match="k: pair 1"):
        c.relation(1)


def test_add_keeps_the_shape_where_it_is_without_position():
    world = pc.World()
    i = world.add(TEMPLATES[0])
    assert world.body(i).shape is TEMPLATES[0]
    j = world.add(TEMPLATES[0], angle=math.pi)
    assert np.allclose(world.body(j).shape.centroid, TEMPLATES[0].centroid)


def test_bodies_keep_name_motion_and_stable_ids():
    world = pc.World()
    m = pc.Motion(velocity=(1, 0))
    ids = [world.add(TEMPLATES[3], (i, 0), name=f"b{i}", motion=m) for i in range(3)]
    world.remove(ids[1])
    k = world.add(TEMPLATES[3], (9, 9))
    assert k == 3 and world.ids.tolist() == [0, 2, 3]
    assert [(b.id, b.name, b.motion) for b in world.bodies()][:2] == [(0, "b0", m), (2, "b2", m)]


def test_many_moves_and_removes_keep_the_index_right():
    # Enough bodies to grow and rebuild the hash table and compact the coordinates.
    rng = np.random.default_rng(3)
    world = pc.World()
    for _ in range(400):
        world.add(TEMPLATES[int(rng.integers(5))], rng.uniform(0, 40, 2))
    for step in range(2000):
        ids = world.ids
        i = int(ids[rng.integers(len(ids))])
        if step % 3 == 0:
            world.remove(i)
            world.add(TEMPLATES[int(rng.integers(5))], rng.uniform(0, 40, 2))
        else:
            world.move(i, rng.uniform(0, 40, 2), float(rng.uniform(0, 6)))
    got = world.contacts()
    pairs, states = brute_contacts(world)
    assert got.pairs.tolist() == [list(p) for p in pairs]
    assert got.states.tolist() == states


def test_bodies_of_very_different_sizes():
    world = pc.World()
    big = world.add(pc.Shape([(0, 0), (1000, 0), (1000, 1000), (0, 1000)]))
    small = [world.add(TEMPLATES[3], (x, 1000.5)) for x in (0.5, 10.25, 999.5, 1001.0)]
    tiny = world.add(TEMPLATES[3].moved((0, 0)), (500, 500))
    got = world.contacts()
    pairs, states = brute_contacts(world)
    assert got.pairs.tolist() == [list(p) for p in pairs] and got.states.tolist() == states
    assert [big, tiny] in got.pairs.tolist() and [big, small[0]] in got.pairs.tolist()


def test_feasible_region_is_where_the_shape_fits():
    world = pc.World(pc.Shape([(0, 0), (6, 0), (6, 3), (0, 3)]))
    world.add(TEMPLATES[0], (2, 1.5))
    sq = TEMPLATES[3]
    region = world.feasible_region(sq)
    assert not region.is_empty
    for x in np.linspace(0, 6, 25):
        for y in np.linspace(0, 3, 13):
            q = world.query(sq, (x, y))
            inside = region.distance(shapely.Point(x, y)) < 1e-9
            interior = region.buffer(-1e-6).contains(shapely.Point(x, y))
            if interior:
                assert q.fits, (x, y)
            if not inside:
                assert not q.fits, (x, y)


def test_feasible_region_keeps_an_exact_fit():
    # A 1x1 square fits exactly in a 1x1 notch between two bodies: a point.
    world = pc.World(pc.Shape([(0, 0), (3, 0), (3, 1), (0, 1)]))
    world.add(TEMPLATES[3], (0.5, 0.5))
    world.add(TEMPLATES[3], (2.5, 0.5))
    region = world.feasible_region(TEMPLATES[3])
    assert region.geom_type == "Point" and list(region.coords) == [(1.5, 0.5)]
    assert world.query(TEMPLATES[3], (1.5, 0.5)).fits


def test_feasible_region_needs_a_container():
    with pytest.raises(ValueError, match="no container"):
        pc.World().feasible_region(TEMPLATES[3])


def test_bad_input_is_refused_with_the_argument_named():
    world = pc.World()
    i = world.add(TEMPLATES[3])
    with pytest.raises(KeyError, match="id: no body 7"):
        world.move(7, (0, 0))
    with pytest.raises(KeyError, match="id: no body 7"):
        world.remove(7)
    with pytest.raises(ValueError, match="position"):
        world.add(TEMPLATES[3], (0, float("nan")))
    with pytest.raises(ValueError, match="angle"):
        world.move(i, (0, 0), float("inf"))
    with pytest.raises(TypeError, match="motion"):
        world.add(TEMPLATES[3], motion=(1, 0))
    with pytest.raises(ValueError, match="positions"):
        world.query_many(TEMPLATES[3], [1.0, 2.0])
    with pytest.raises(ValueError, match="angles"):
        world.query_many(TEMPLATES[3], [(1.0, 2.0)], [0.0, 1.0])
    with pytest.raises(ValueError, match="tolerance"):
        world.contacts(tolerance=-1.0)
    with pytest.raises(ValueError, match="position: .* beyond"):
        world.add(TEMPLATES[3], (1e200, 0))


def test_an_empty_world_answers():
    world = pc.World(CONTAINER)
    assert len(world.contacts()) == 0
    assert world.query(TEMPLATES[3], (1, 1)).fits
    assert world.query_many(TEMPLATES[3], [(1, 1), (-5, 0)]).tolist() == [0, 2]


def _layouts():
    if not (DATASETS / "layouts").is_dir():
        return []
    return sorted((DATASETS / "layouts").glob("*.json"))


@pytest.mark.skipif(not _layouts(), reason="shared datasets absent")
@pytest.mark.parametrize("path", _layouts(), ids=lambda p: p.stem)
def test_published_layouts_are_feasible(path):
    data = json.loads(path.read_text())
    world = pc.World(pc.Shape(data["container"]))
    for k, item in enumerate(data["placed"]):
        world.add(pc.Shape(item["vertices"]), name=str(k))
    got = world.contacts()
    assert not (got.states == 2).any(), got.penetrating_pairs.tolist()
    assert not (got.container_states == 2).any(), got.container_ids.tolist()


def test_add_many_equals_add_one_by_one():
    rng = np.random.default_rng(11)
    rings = [TEMPLATES[int(rng.integers(5))].exterior + rng.integers(0, 30, 2) / 2
             for _ in range(200)]
    rings += [r[::-1].copy() for r in rings[:20]]  # clockwise raw rings
    shapes = [TEMPLATES[2].moved((3.0, 4.0)), TEMPLATES[2].moved((5.0, 4.0))]
    one = pc.World()
    for r in rings + shapes:
        one.add(r)
    many = pc.World()
    ids = many.add_many(rings + shapes, names=[str(k) for k in range(len(rings) + 2)])
    assert ids.tolist() == list(range(len(rings) + 2)) and many.body(5).name == "5"
    a, b = one.contacts(), many.contacts()
    assert a.pairs.tolist() == b.pairs.tolist() and a.states.tolist() == b.states.tolist()
    assert (a.tolerances == b.tolerances).all()
    pairs, states = brute_contacts(many)
    assert b.pairs.tolist() == [list(p) for p in pairs] and b.states.tolist() == states


def test_a_contacts_answer_keeps_the_poses_it_was_computed_at():
    world = pc.World()
    world.add_many(np.stack([TEMPLATES[3].exterior, TEMPLATES[3].exterior + (1.0, 0.0)]))
    c = world.contacts()
    world.move(1, (9.0, 9.0))
    assert c.relation(0).state == pc.State.CONTACT
    assert len(world.contacts()) == 0


def _write(tmp_path, data, name="layout.json"):
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return str(path)


SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]


def _layout():
    return {"container": [[0, 0], [4, 0], [4, 2], [0, 2]],
            "placed": [{"item": 0, "vertices": SQ},
                       {"item": 0, "vertices": [[x + 1, y] for x, y in SQ]},
                       {"item": 1, "vertices": [[x + 1.5, y + 0.5] for x, y in SQ]},
                       {"item": 1, "vertices": [[x + 3.5, y] for x, y in SQ]}]}


def test_cli_contacts_lists_pairs_and_container(tmp_path, capsys):
    from polycontact.cli import main

    assert main(["contacts", _write(tmp_path, _layout()), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    got = [(p["a"], p["b"], p["state"]) for p in rep["contacts"]]
    assert got == [(0, 1, "contact"), (1, 2, "penetrating")]
    assert [(c["body"], c["state"]) for c in rep["container_contacts"]] == [
        (0, "contact"), (1, "contact"), (3, "outside")]
    assert main(["contacts", _write(tmp_path, _layout())]) == 0
    out = capsys.readouterr().out
    assert "pairs: 2 (1 in contact, 1 penetrating)" in out and "3 (1): outside" in out


def test_cli_contacts_without_container_and_plot(tmp_path, capsys):
    from polycontact.cli import main

    data = {"bodies": [{"name": "a", "vertices": SQ}, {"name": "b", "vertices": SQ}]}
    png = tmp_path / "c.png"
    assert main(["contacts", _write(tmp_path, data), "--plot", str(png)]) == 0
    assert "0 (a) and 1 (b): penetrating" in capsys.readouterr().out
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize("data, message", [
    ({"items": {}}, "expected an object with 'placed' or 'bodies'"),
    ({"placed": [{"item": 0}]}, "body 0: expected an object with 'vertices'"),
    ({"placed": [{"vertices": [[0, 0], [1, 1], [1, 0], [0, 1]]}]}, "body 0: outer loop: self"),
    ({"container": [[0, 0], [1, 1]], "placed": []}, "container: "),
])
def test_cli_contacts_refuses_bad_layouts(tmp_path, capsys, data, message):
    from polycontact.cli import main

    assert main(["contacts", _write(tmp_path, data)]) == 2
    err = capsys.readouterr().err
    assert message in err and "layout.json" in err


def test_feasible_region_avoids_the_container_holes():
    world = pc.World(CONTAINER)
    region = world.feasible_region(TEMPLATES[3].exterior)  # an array: not cached
    assert not region.contains(shapely.Point(6, 5))        # the hole (5..7, 4..6)
    assert region.distance(shapely.Point(6, 3.5)) < 1e-9   # touching the hole from below
    assert world.query(TEMPLATES[3], (6, 3.5)).fits and not world._nfp_cache
    world.add(TEMPLATES[0], (2, 2))
    region = world.feasible_region(TEMPLATES[3])
    assert not region.contains(shapely.Point(2, 2)) and len(world._nfp_cache) == 1


class _Terminal:
    """A stderr that says it is a terminal (tqdm draws its bar only there)."""

    def __init__(self) -> None:
        self.text = ""

    def write(self, s: str) -> int:
        self.text += s
        return len(s)

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return True


def test_contacts_cli_shows_progress_reading_a_long_layout_on_a_terminal(tmp_path, monkeypatch):
    import sys

    from polycontact.cli import contacts as cli_contacts

    sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    path = tmp_path / "layout.json"
    path.write_text(json.dumps({"placed": [{"item": k, "vertices": [[x + 2 * k, y] for x, y in sq]}
                                           for k in range(5)]}))
    monkeypatch.setattr(cli_contacts, "PROGRESS_MIN_BODIES", 3)
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    _, quiet, _ = cli_contacts.read_layout(str(path), progress=False)
    assert term.text == ""
    _, bodies, names = cli_contacts.read_layout(str(path), progress=True)
    assert "reading bodies" in term.text and len(bodies) == len(quiet) == 5
    assert names == [f"{k} ({k})" for k in range(5)]


@pytest.mark.parametrize("scan", [0, 10**9], ids=["grid", "box scan"])
def test_bodies_centred_on_cell_edges_are_found(monkeypatch, scan):
    # query_many goes through the grid, or (few bodies) tests every body's box: both.
    monkeypatch.setattr(world_module, "_SCAN_BODIES", scan)
    # Squares of side 1 and 2 (box side exactly a power of two: half a cell out of their
    # own cell) with box centres on cell edges and between them, touching and
    # overlapping: the broad phase's cell range must keep every neighbour.
    # The first body sets the grid's origin (its centre). Bodies are added from the top
    # right down, so a pair (i < j) is found from the body up and right: a cell range
    # cut short on its low side would lose it.
    world = pc.World()
    unit = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    two = pc.Shape([(0, 0), (2, 0), (2, 2), (0, 2)])
    world.add(unit, (0.5, 0.5))
    for x in range(5, -1, -1):
        for y in range(3, -1, -1):
            world.add(unit, (0.5 + x, 0.5 + y))
            world.add(unit, (8.375 + x, 0.375 + y))  # centres just below cell edges
    for x in range(3):
        world.add(two, (1.0 + 2 * x, 5.0))
        world.add(unit, (1.0 + 2 * x, 6.5))
        world.add(two, (0.5 + 2 * x, -1.0))
    got = world.contacts()
    pairs, states = brute_contacts(world)
    assert got.pairs.tolist() == [list(p) for p in pairs] and got.states.tolist() == states
    probes = [(unit, (x / 8, y / 8)) for x in range(-8, 120, 3) for y in range(-40, 60, 3)]
    probes += [(two, (x / 4, y / 4)) for x in range(-4, 60) for y in range(-20, 30)]
    for shape in (unit, two):
        pos = [p for s, p in probes if s is shape]
        many = world.query_many(shape, pos)
        one = [max([0, *world.query(shape, p).states.tolist()]) for p in pos]
        assert many.tolist() == one


@pytest.mark.parametrize("scan", [0, 10**9], ids=["grid", "box scan"])
def test_query_many_tests_the_container_last_with_the_same_answer(monkeypatch, scan):
    monkeypatch.setattr(world_module, "_SCAN_BODIES", scan)
    # query_many tests the container's box, then the bodies, then (only if no body is
    # penetrated) the container's outline and holes: every mix of the three gives the
    # worst state that query gives.
    world = pc.World(CONTAINER)
    world.add(TEMPLATES[3], (2.5, 2.5))
    world.add(TEMPLATES[0], (9.0, 7.0))
    sq = TEMPLATES[3]
    cases = {
        (-1.0, 5.0): 2,   # off the container's box
        (0.25, 5.0): 2,   # crosses the outline, box inside the container's box
        (0.5, 5.0): 1,    # touches the outline only
        (6.0, 5.0): 2,    # in the hole
        (4.5, 5.0): 1,    # touches the hole only
        (3.5, 2.5): 1,    # touches a body only
        (2.75, 2.5): 2,   # penetrates a body
        (3.5, 3.5): 1,    # corner contact with a body
        (1.5, 0.5): 1,    # touches a body and the outline
        (2.0, 0.25): 2,   # penetrates a body and crosses the outline
        (3.0, 7.0): 0,    # free
    }
    pos = list(cases)
    many = world.query_many(sq, pos)
    one = []
    for p in pos:
        q = world.query(sq, p)
        one.append(max([q.container_state, *q.states.tolist()]))
    assert many.tolist() == one == list(cases.values())


@pytest.mark.parametrize("count", [3, 40], ids=["level scanned", "cells visited"])
def test_contacts_each_pair_once_with_a_wide_tolerance(count):
    # Unit squares with gaps of 0.4 (contact under tolerance 0.5) and 0.6 (apart): the
    # wide tolerance widens each body's block of cells; with few bodies on the level the
    # level is scanned body by body instead. Every pair is found, once.
    world = pc.World()
    unit = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    side = math.ceil(math.sqrt(count))
    for k in range(count):
        x, y = k % side, k // side
        world.add(unit, (1.4 * x + 0.2 * (y % 2), 1.5 * y + (0.1 if x % 3 == 0 else 0.0)))
    for tol in (0.5, None):
        got = world.contacts(tolerance=tol)
        pairs, states = brute_contacts(world, tol)
        assert got.pairs.tolist() == [list(p) for p in pairs] and got.states.tolist() == states
    assert len(world.contacts(tolerance=0.5)) > 0


def test_contacts_in_merged_far_cells():
    # Cell indices are clamped 2**25 cells from the first body: these small squares, far
    # away, share clamped cells; touching and overlapping pairs are still found, once.
    world = pc.World()
    world.add(pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)]))
    s = 2.0**-10
    small = pc.Shape(np.array([(0, 0), (1, 0), (1, 1), (0, 1)]) * s)
    for k in range(12):
        world.add(small, (1e5 + s * (k % 4) * (1.0 if k < 8 else 0.5), 1e5 + s * (k // 4)))
        world.add(small, (-1e5 - s * k, -1e5 + s * (k % 3) * 0.75))
    got = world.contacts()
    pairs, states = brute_contacts(world)
    assert got.pairs.tolist() == [list(p) for p in pairs] and got.states.tolist() == states
    assert (got.states == 1).any() and (got.states == 2).any()
