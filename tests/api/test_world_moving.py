"""World.first_impacts / first_impact and Scene.first_impact of three or more bodies
equal the loop of time_of_impact over every pair (ids in the world's numbering)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact import scene as sc
from polycontact.impacts import event_time

SQ = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
ELL = pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])


def _brute(world: pc.World, t_max: float) -> list:
    out = []
    bodies = world.bodies()
    for k, a in enumerate(bodies):
        for b in bodies[k + 1:]:
            imp = pc.time_of_impact(a.shape, a.motion or pc.Motion(), b.shape,
                                    b.motion or pc.Motion(), t_max=t_max)
            if imp.state is not None or imp.status is not pc.ImpactStatus.NO_HIT:
                out.append((a.id, b.id, imp))
    return out


def _first_order(imp: pc.Impact) -> tuple[float, float]:
    """The order of the first event: collisions (penetrating at the start, hits,
    searches without a verdict) by time before any touch, touches by time."""
    touch_only = imp.status is pc.ImpactStatus.NO_HIT
    when = event_time(imp)
    return (math.inf if touch_only else when, when if touch_only else 0.0)


def _same(got: list, want: list) -> bool:
    """The same pairs and statuses, times within the time tolerance (the batch kernel
    may round a last place differently: see test_impacts_many.agree)."""
    g = {(i, j): imp for i, j, imp in got}
    w = {(i, j): imp for i, j, imp in want}
    return g.keys() == w.keys() and all(
        g[k].status is w[k].status and g[k].state is w[k].state
        and (g[k].time is None) == (w[k].time is None)
        and (g[k].time is None or abs(g[k].time - w[k].time) <= w[k].time_tolerance)
        for k in w)


@examples(15)
@given(st.lists(st.tuples(st.integers(0, 6), st.integers(0, 3), st.sampled_from([0, 1, 2]),
                          st.floats(-2, 2), st.floats(-2, 2), st.floats(-1, 1)),
                min_size=3, max_size=7),
       st.sets(st.integers(0, 6), max_size=2))
def test_world_first_impacts_equal_the_pairwise_loop(spec, removed):
    w = pc.World()
    for x, y, kind, vx, vy, om in spec:
        shape = (SQ, ELL, SQ.moved((0.25, 0.1)))[kind]
        motion = pc.Motion(velocity=(vx, vy), angular_velocity=om) if kind != 2 else None
        w.add(shape, (1.5 * x, 1.5 * y), motion=motion)
    for k in removed:
        if k in w and len(w) > 2:
            w.remove(k)
    got = w.first_impacts(t_max=3.0)
    want = _brute(w, 3.0)
    assert _same(got, want)
    first = w.first_impact(t_max=3.0)
    if not want:
        assert first is None
    else:
        assert first is not None and first[:2] in {(i, j) for i, j, _ in want}


def test_world_first_impact_ids_survive_removal():
    w = pc.World()
    w.add(SQ, (0.5, 0.5))                               # id 0, removed below
    a = w.add(SQ, (10.5, 0.5), motion=pc.Motion(velocity=(1, 0)))
    b = w.add(SQ, (13.5, 0.5))
    w.remove(0)
    i, j, imp = w.first_impact(t_max=5)
    assert (i, j) == (a, b) and abs(imp.time - 2.0) <= imp.time_tolerance


def test_scene_of_three_bodies_first_impact_equals_the_loop():
    bodies = (
        sc.SceneBody("a", SQ, pc.Motion(velocity=(1, 0))),
        sc.SceneBody("b", SQ.moved((3, 0)), pc.Motion()),
        sc.SceneBody("c", SQ.moved((0, 4)), pc.Motion(velocity=(1, -2))),   # falls onto a
        sc.SceneBody("d", SQ.moved((30, 30)), pc.Motion()),
    )
    scene = sc.Scene(bodies, 5.0)
    i, j, imp = scene.first_impact()
    loop = [(x, y, pc.time_of_impact(x.shape, x.motion, y.shape, y.motion, t_max=5.0))
            for k, x in enumerate(bodies) for y in bodies[k + 1:]]
    wa, wb, wimp = min(loop, key=lambda r: _first_order(r[2]))
    assert (bodies[i].name, bodies[j].name) == (wa.name, wb.name)
    assert imp.time == wimp.time and imp.status is wimp.status
    assert np.isclose(imp.time, 1.5, atol=1e-4)        # c lands on a at t = 1.5
