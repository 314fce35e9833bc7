"""A time window far longer than the time to the hit changes nothing.

The tolerances of the time-of-impact search are local to the time examined, never scaled
by ``t_max``: the broad phase widens the bounding circles by the rounding of the
positions at each time, and the exact search reads its tolerances over windows that end
where the bodies' coordinates at most double. The oracle is analytic: a square
translating towards a still square first overlaps it when the gap closes, at
``gap / speed``, and from then on overlaps it by ``speed × (t − gap / speed)``.
"""

from __future__ import annotations

import json
import math

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact.cli import main

SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
ULP = 2.0**-52


def _eps(size: float, magnitude: float) -> float:
    """The distance tolerance (``tolerance_for``) of bodies of ``size`` whose coordinates'
    terms reach ``magnitude``."""
    return max(1e-12 * size, 64 * ULP * magnitude)


def test_a_long_window_keeps_the_hit():
    a, b = pc.Shape(SQ), pc.Shape(SQ + [3, 0])
    go, still = pc.Motion(velocity=(1, 0)), pc.Motion()
    for t_max in (5.0, 1e25, 1e27, 1e50):
        hit = pc.time_of_impact(a, go, b, still, t_max=t_max)
        assert hit.collides and 2.0 <= hit.time <= 2.0 + 1e-4 + 1e-12, (t_max, hit)
        # the circles are widened by the rounding of the positions at each time, never
        # by the rounding at t_max: the same interval, to a few units of 2**-52
        assert np.allclose(hit.broad_phase, ((1.5857864376254904, 4.41421356237451),),
                           rtol=1e-14, atol=0.0), hit.broad_phase
        fast = pc.time_of_impact(a, pc.Motion(velocity=(1e6, 0)), b, still, t_max=t_max)
        assert fast.collides and fast.time <= 2e-6 + 1e-4
    (i, j, first), = pc.first_impacts([a, b], [go, still], t_max=1e27)
    assert (i, j) == (0, 1) and first.collides and abs(first.time - 2.0) <= 1e-4
    world = pc.World()
    world.add(a, motion=go)
    world.add(b)
    _, _, impact = world.first_impact(t_max=1e27)
    assert impact.collides and abs(impact.time - 2.0) <= 1e-4


def test_a_long_window_keeps_the_hit_on_the_command_line(tmp_path, capsys):
    scene = {"t_max": 1e27, "bodies": [
        {"name": "a", "vertices": SQ.tolist(), "velocity": [1, 0]},
        {"name": "b", "vertices": (SQ + [3, 0]).tolist()}]}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    assert main(["collide", str(path), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["collides"] and abs(rep["time"] - 2.0) <= 1e-4


@st.composite
def long_windows(draw):
    size = 10.0 ** draw(st.integers(-6, 6))
    gap = size * draw(st.floats(0.01, 100.0))
    speed = 10.0 ** draw(st.floats(-6, 12))
    offset = draw(st.sampled_from([0.0, 1.0, -1e3, 1e6, -1e9])) * size
    lateral = size * draw(st.floats(-0.9, 0.9))
    common = draw(st.sampled_from([0.0, 0.0, 1.0, 1e3]))  # both move: far from the origin
    # up to the documented limit: coordinates reach at most 1e100 within t_max
    t_hit = gap / speed
    reach = abs(offset) + 3 * size + gap + (1 + common) * speed * t_hit
    top = math.log10(1e99 / ((1 + common) * speed + reach))
    t_max = t_hit * 4 + 10.0 ** draw(st.floats(min(0.0, top), top))
    return size, gap, speed, offset, lateral, common, t_max


@given(long_windows())
@example((1.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1e27))        # the window that lost the hit
@example((1.0, 2.0, 1e6, 0.0, 0.0, 0.0, 1e21))
@example((1e-6, 2e-6, 1e-6, 0.0, 0.0, 0.0, 1e80))
@example((1e6, 2e6, 1e12, -1e15, 0.5e6, 1e3, 1e80))
@examples(150)
def test_the_hit_does_not_depend_on_t_max(case):
    size, gap, speed, offset, lateral, common, t_max = case
    a = pc.Shape(SQ * size + [offset, 0.0])
    b = pc.Shape(SQ * size + [offset + size + gap, lateral])
    ma = pc.Motion(velocity=((1 + common) * speed, 0.0))
    mb = pc.Motion(velocity=(common * speed, 0.0))
    t_hit = gap / speed
    short = 4 * t_hit
    for window in (short, t_max):
        hit = pc.time_of_impact(a, ma, b, mb, t_max=window)
        # the first time the overlap is deeper than the tolerance there (the terms of
        # the coordinates reach |offset| + the travel + the gap and the size)
        mag = abs(offset) + 3 * size + gap + (1 + common) * speed * 2 * t_hit
        deep = t_hit + 3 * _eps(size, mag) / speed
        assert hit.status is pc.ImpactStatus.HIT, (window, hit)
        assert t_hit - _eps(size, mag) / speed <= hit.time, (window, hit, t_hit)
        assert hit.time <= deep + hit.time_tolerance + 4 * ULP * deep, (window, hit, t_hit)
        # the circles overlap until A has passed B: never longer with a longer window
        assert hit.broad_phase[0][0] <= t_hit <= hit.broad_phase[0][1]
        assert hit.broad_phase[-1][1] <= (gap + 4 * size) / speed, (window, hit.broad_phase)
