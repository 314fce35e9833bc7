"""API calls refuse bad arguments at the door, with an error naming the argument, not
deep inside (a Numba typing error, an integer overflow, an iteration over None)."""

from __future__ import annotations

import json
import re

import pytest

import polycontact as pc

SQ = [(0, 0), (1, 0), (1, 1), (0, 1)]


def test_world_ids_are_integers():
    world = pc.World()
    world.add(SQ)
    for call in (lambda: world.move(0.0, (1, 1)), lambda: world.remove(0.0),
                 lambda: world.body(0.0), lambda: world.move(True, (1, 1))):
        with pytest.raises(TypeError, match="^id: expected an integer, got"):
            call()
    assert len(world) == 1 and world.body(0).position.tolist() == [0.5, 0.5]
    with pytest.raises(TypeError, match="^k: expected an integer"):
        world.contacts().relation(0.0)


@pytest.mark.parametrize("name", ["max_iterations", "samples"])
def test_counts_beyond_what_the_search_takes_are_refused(name):
    a = pc.Shape(SQ)
    with pytest.raises(ValueError, match=f"^{name}: expected an integer from"):
        pc.time_of_impact(a, pc.Motion(velocity=(1, 0)), a.moved((3, 0)), pc.Motion(),
                          t_max=5.0, **{name: 2**70})
    with pytest.raises(TypeError, match=f"^{name}: expected an integer"):
        pc.time_of_impact(a, pc.Motion(velocity=(1, 0)), a.moved((3, 0)), pc.Motion(),
                          t_max=5.0, **{name: 10.0})


@pytest.mark.parametrize("key, where", [
    ("t_max", "t_max"), ("velocity", "bodies[0].velocity[0]"),
    ("vertices", "bodies[0].vertices[0][0]"), ("angular_velocity", "bodies[0].angular_velocity")])
def test_a_scene_with_a_huge_integer_is_refused_naming_the_key(tmp_path, key, where):
    huge = 10**400
    scene = {"t_max": 5, "bodies": [{"name": "a", "vertices": [list(p) for p in SQ]},
                                    {"name": "b", "vertices": [[3, 0], [4, 0], [4, 1], [3, 1]]}]}
    if key == "t_max":
        scene["t_max"] = huge
    elif key == "velocity":
        scene["bodies"][0]["velocity"] = [huge, 0]
    elif key == "vertices":
        scene["bodies"][0]["vertices"][0] = [huge, 0]
    else:
        scene["bodies"][0]["angular_velocity"] = huge
    with pytest.raises(pc.InvalidSceneError, match="^" + re.escape(where)):
        pc.load_scene(scene)
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(pc.InvalidSceneError, match="^" + re.escape(f"{path}: {where}")):
        pc.load_scene(path)


def test_none_holes_mean_no_holes():
    assert pc.Shape(SQ, None).holes == () and pc.Shape(SQ, None).area == 1.0


def test_a_hole_outside_its_shell_is_named_by_the_callers_vertex():
    # the counter-clockwise hole is stored clockwise: its stored vertex 0 is the
    # caller's vertex 2, (6, 6); the message names the caller's vertex 0, at (5, 5)
    message = r"^hole 0 lies outside the outer loop \(its vertex 0 is at \(5, 5\)\)"
    with pytest.raises(pc.InvalidShapeError, match=message):
        pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(5, 5), (6, 5), (6, 6)]])
