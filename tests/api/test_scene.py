"""Scene files: loading, validation with the key named, first impact among pairs."""

import json
import math

import pytest

import polycontact as pc
from polycontact import ImpactStatus, InvalidSceneError

SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]


def body(name, dx=0.0, dy=0.0, **motion):
    return {"name": name, "vertices": [[x + dx, y + dy] for x, y in SQ], **motion}


def write(tmp_path, data, name="scene.json"):
    path = tmp_path / name
    path.write_text(json.dumps(data) if not isinstance(data, str) else data)
    return path


def test_load_paper_case_1():
    scene = pc.load_scene("examples/paper-case-1.json")
    assert [b.name for b in scene.bodies] == ["red", "blue"]
    assert scene.t_max == 20 and scene.time_tolerance == 1e-4
    red, blue = scene.bodies
    assert red.motion.angular_velocity == pytest.approx(-math.pi / 2)
    assert blue.motion.velocity == (-10.0, 0.0)
    assert red.shape.centroid.round(2).tolist() == [0.32, -4.75]       # the paper's value
    assert blue.shape.centroid.round(2).tolist() == [312.55, 20.12]    # paper: 312.54


def test_paper_case_2_needs_repair_and_says_where():
    with pytest.raises(InvalidSceneError, match=r"paper-case-2.json: bodies\[0\]\.vertices "
                       r"\('red'\): outer loop: self-intersection at \(10\.20\d*, -6\.37\d*\)"):
        pc.load_scene("examples/paper-case-2.json")
    scene = pc.load_scene("examples/paper-case-2.json", repair=True)
    assert scene.bodies[0].shape.repairs and not scene.bodies[1].shape.repairs


def test_radians_and_degrees_and_defaults(tmp_path):
    scene = pc.load_scene(write(tmp_path, {"t_max": 1, "bodies": [
        body("a", angular_velocity=1.5, angular_acceleration_deg=90),
        {"vertices": SQ, "holes": []}]}))
    a, b = scene.bodies
    assert a.motion.angular_velocity == 1.5
    assert a.motion.angular_acceleration == pytest.approx(math.pi / 2)
    assert b.name == "body1" and b.motion == pc.Motion()
    assert scene.time_tolerance is None


@pytest.mark.parametrize(
    "data, message",
    [
        ({"bodies": [body("a"), body("b", 3)]}, "t_max: missing"),
        ({"t_max": "10", "bodies": [body("a"), body("b", 3)]}, "t_max: expected a number"),
        ({"t_max": -1, "bodies": [body("a"), body("b", 3)]}, "t_max: expected a number >= 0"),
        ({"t_max": 1, "bodies": [body("a")]}, "bodies: expected at least two bodies"),
        ({"t_max": 1}, "bodies: missing"),
        ({"t_max": 1, "bodies": {}}, "bodies: expected a list"),
        ({"t_max": 1, "bodies": [body("a"), body("b", 3)], "colour": 1}, "colour: unknown key"),
        ({"t_max": 1, "bodies": [body("a"), body("b", 3, spin=1)]},
         r"bodies\[1\]\.spin: unknown key"),
        ({"t_max": 1, "bodies": [body("a"), {"name": "b"}]}, r"bodies\[1\]\.vertices: missing"),
        ({"t_max": 1, "bodies": [body("a", velocity=[1]), body("b", 3)]},
         r"bodies\[0\]\.velocity: expected \[x, y\]"),
        ({"t_max": 1, "bodies": [body("a", velocity=[1, True]), body("b", 3)]},
         r"bodies\[0\]\.velocity\[1\]: expected a number"),
        ({"t_max": 1, "bodies": [body("a", angular_velocity=1, angular_velocity_deg=2),
                                 body("b", 3)]}, "not both"),
        ({"t_max": 1, "bodies": [body("a"), body("a", 3)]}, r"bodies\[1\]\.name: duplicate"),
        ({"t_max": 1, "time_tolerance": 0, "bodies": [body("a"), body("b", 3)]},
         "time_tolerance"),
        ({"t_max": 1, "bodies": [body("a"), {"name": "b", "vertices": [[0, 0], [1, 1]]}]},
         r"bodies\[1\]\.vertices \('b'\): outer loop: fewer than 3"),
        ({"t_max": 1, "bodies": [body("a"), {"name": "b", "vertices": [[0, 0], [1, "x"]]}]},
         r"bodies\[1\]\.vertices\[1\]\[1\]: expected a number"),
        ([1, 2], "expected a JSON object"),
    ],
)
def test_bad_scenes_name_the_key(tmp_path, data, message):
    with pytest.raises(InvalidSceneError, match=message):
        pc.load_scene(write(tmp_path, data))


def test_nan_and_bad_json(tmp_path):
    nan = '{"t_max": 1, "bodies": [{"vertices": [[0,0],[1,0],[1,1]], "velocity": [NaN, 0]},' \
          ' {"vertices": [[5,0],[6,0],[6,1]]}]}'
    with pytest.raises(InvalidSceneError, match=r"bodies\[0\]\.velocity\[0\]: expected a finite"):
        pc.load_scene(write(tmp_path, nan))
    with pytest.raises(InvalidSceneError, match="not valid JSON"):
        pc.load_scene(write(tmp_path, "{"))
    with pytest.raises(InvalidSceneError, match="cannot read"):
        pc.load_scene(tmp_path / "missing.json")


def test_first_impact_among_three_bodies():
    scene = pc.Scene.from_dict({"t_max": 10, "bodies": [
        body("left", velocity=[1, 0]),
        body("far", 20, 0),
        body("right", 5, 0, velocity=[-1, 0]),
    ]})
    i, j, impact = scene.first_impact()
    assert (scene.bodies[i].name, scene.bodies[j].name) == ("left", "right")
    assert impact.time == pytest.approx(2.0, abs=1e-4)


def test_first_impact_prefers_penetration_at_start_and_reports_contacts():
    scene = pc.Scene.from_dict({"t_max": 10, "bodies": [
        body("a", velocity=[1, 0]), body("b", 5, 0), body("c", 20.5, 0), body("d", 20, 0)]})
    i, j, impact = scene.first_impact()
    assert (scene.bodies[i].name, scene.bodies[j].name) == ("c", "d")
    assert impact.status is ImpactStatus.PENETRATING_AT_START
    touching = pc.Scene.from_dict({"t_max": 1, "bodies": [body("a"), body("b", 1, 0)]})
    assert touching.first_impact().impact.first_contact == 0.0
