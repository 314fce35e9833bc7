"""One API shape across the public names (docs/conventions.rst, "API shape"): the end
of a time window is keyword-only, options are spelled out (no ``**options``), the
arrays of a batch result are named in the plural, public signatures return concrete
types, and a pair of moving bodies is one record everywhere."""

from __future__ import annotations

import dataclasses
import inspect
import typing

import numpy as np
import pytest

import polycontact as pc
from polycontact import plotting

SQ = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])


def _callables() -> dict[str, typing.Callable[..., object]]:
    """Every public function, and every public method of a public class."""
    found: dict[str, typing.Callable[..., object]] = {}
    for name in pc.__all__:
        obj = getattr(pc, name)
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if member.startswith("_"):
                    continue
                value = getattr(value, "__func__", value)
                if inspect.isfunction(value):
                    found[f"{name}.{member}"] = value
        elif inspect.isfunction(obj):
            found[name] = obj
    for name in plotting.__all__:
        found[f"plotting.{name}"] = getattr(plotting, name)
    return found


def test_the_end_of_a_time_window_is_keyword_only():
    takes = {name: inspect.signature(f).parameters["t_max"]
             for name, f in _callables().items() if "t_max" in inspect.signature(f).parameters}
    assert {"time_of_impact", "first_impacts", "first_impact", "World.first_impacts"} <= set(takes)
    assert [n for n, p in takes.items() if p.kind is not p.KEYWORD_ONLY] == []


def test_options_are_spelled_out():
    """No ``**options``: only drawing passes matplotlib's style keywords on."""
    style = {"Shape.plot", "plotting.plot_shape"}
    loose = [name for name, f in _callables().items()
             if any(p.kind is p.VAR_KEYWORD for p in inspect.signature(f).parameters.values())]
    assert sorted(loose) == sorted(style)


def test_the_moving_bodies_family_takes_the_options_of_time_of_impact():
    options = {name: p.default for name, p in
               inspect.signature(pc.time_of_impact).parameters.items()
               if p.kind is p.KEYWORD_ONLY and name != "t_max"}
    for f in (pc.first_impacts, pc.first_impact, pc.World.first_impacts,
              pc.World.first_impact, pc.time_of_impact_many):
        params = inspect.signature(f).parameters
        assert {k: params[k].default for k in options} == options, f.__qualname__
    for f in (pc.Scene.first_impact, pc.Scene.impacts):   # the scene's own tolerance
        params = inspect.signature(f).parameters
        assert {k: params[k].default for k in options if k != "time_tolerance"} == {
            k: v for k, v in options.items() if k != "time_tolerance"}, f.__qualname__
        assert params["time_tolerance"].default is None


@pytest.mark.parametrize("cls", [pc.ImpactBatch, pc.RelationBatch, pc.Contacts, pc.Sweep,
                                 pc.Query])
def test_the_arrays_of_a_batch_are_named_in_the_plural(cls):
    hints = typing.get_type_hints(cls)
    arrays = [f.name for f in dataclasses.fields(cls)
              if not f.name.startswith("_") and hints[f.name] is np.ndarray]
    arrays += [name for name, value in vars(cls).items()
               if not name.startswith("_") and isinstance(value, (property,))
               and typing.get_type_hints(value.fget).get("return") is np.ndarray]
    assert arrays and [n for n in arrays if not n.endswith("s")] == []


def test_public_signatures_return_concrete_types():
    vague = [name for name, f in _callables().items()
             if inspect.signature(f).return_annotation in ("Any", typing.Any)]
    assert vague == []


def test_a_pair_of_moving_bodies_is_one_record_everywhere():
    """The function, the World (its ids) and the Scene (indices into its bodies) give
    the same PairImpact for the same bodies."""
    go = pc.Motion(velocity=(1, 0))
    shapes, motions = [SQ, SQ.moved((3, 0)), SQ.moved((0, 9))], [go, pc.Motion(), pc.Motion()]
    direct = pc.first_impact(shapes, motions, t_max=5)

    world = pc.World()
    world.add(SQ.moved((50, 50)))                 # id 0, removed: the ids are not indices
    ids = [world.add(s, motion=m) for s, m in zip(shapes, motions)]
    world.remove(0)
    from_world = world.first_impact(t_max=5)

    scene = pc.Scene(tuple(pc.SceneBody(str(k), s, m)
                           for k, (s, m) in enumerate(zip(shapes, motions))), t_max=5)
    from_scene = scene.first_impact()

    for event in (direct, from_world, from_scene, *world.first_impacts(t_max=5),
                  *scene.impacts()):
        assert type(event) is pc.PairImpact
    assert (direct.i, direct.j) == (0, 1) == (from_scene.i, from_scene.j)
    assert (from_world.i, from_world.j) == (ids[0], ids[1])
    assert direct.impact.time == from_world.impact.time == from_scene.impact.time


def test_t_max_given_by_position_is_refused():
    with pytest.raises(TypeError):
        pc.first_impacts([SQ, SQ], [pc.Motion()] * 2, 5)
    with pytest.raises(TypeError):
        pc.World().first_impacts(5)                    
