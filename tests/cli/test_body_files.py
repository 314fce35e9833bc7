"""Body files on the command line: every form a body takes (a bare JSON list of vertices
included), one clear line for a file with no body or a coordinate that is not a number,
and ``collide`` given a body file instead of a scene says so; ``collide --help``
describes the scene format, and its example runs."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import shapely

from polycontact.cli import collide, main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FRAME = str(EXAMPLES / "body-frame.json")
ELL = [[0, 0], [3, 0], [3, 1], [1, 1], [1, 3], [0, 3]]


def _write(tmp_path: Path, name: str, content: str | bytes) -> str:
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return str(path)


def _error(capsys) -> str:
    out, err = capsys.readouterr()
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


@pytest.mark.parametrize(
    "content",
    [
        json.dumps(ELL),                                    # a bare list of vertices
        json.dumps(ELL + [ELL[0]]) + "\n",                  # closed, trailing newline
        json.dumps({"vertices": ELL}),
        shapely.Polygon(ELL).wkt,
        shapely.to_geojson(shapely.Polygon(ELL)),
        shapely.Polygon(ELL).wkb,
        shapely.Polygon(ELL).wkb_hex,
    ],
    ids=["list", "closed-list", "body", "wkt", "geojson", "wkb", "wkb-hex"],
)
def test_every_body_form_in_a_file_gives_the_same_answer(tmp_path, capsys, content):
    assert main(["classify", str(EXAMPLES / "body-ell.json"), FRAME, "--json"]) == 0
    expected = json.loads(capsys.readouterr().out)
    path = _write(tmp_path, "a.json", content)
    assert main(["classify", path, FRAME, "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == expected


@pytest.mark.parametrize("content", ["", "\n", "  \t\n  ", b""])
def test_an_empty_file_says_empty_file(tmp_path, capsys, content):
    path = _write(tmp_path, "empty.json", content)
    assert main(["classify", path, FRAME]) == 2
    line = _error(capsys)
    assert line.startswith(f"polycontact classify: error: {path}: empty file (expected a body")
    assert "WKT" in line and "ParseException" not in line


@pytest.mark.parametrize(
    ("doc", "where"),
    [
        ({"vertices": [[0, 0], [1, "a"], [1, 1]]}, "outer loop: vertex 1: expected real "
                                                   "numbers, got 'a' (str)"),
        ([[0, 0], [1, 0], ["1", 1]], "outer loop: vertex 2: expected real numbers, got '1' (str)"),
        ({"vertices": [[0, 0], [9, 0], [9, 9]], "holes": [[[5, 2], [6, 2], [6, None]]]},
         "hole 0: vertex 2: expected real numbers, got None (NoneType)"),
        ({"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, True], [0, 0]]]},
         "outer loop: vertex 2: expected real numbers, got True (bool)"),
    ],
)
def test_a_coordinate_that_is_not_a_number_is_named_by_loop_and_vertex(tmp_path, capsys, doc,
                                                                      where):
    path = _write(tmp_path, "a.json", json.dumps(doc))
    assert main(["classify", path, FRAME]) == 2
    assert _error(capsys) == f"polycontact classify: error: {path}: {where}"


@pytest.mark.parametrize(
    "content",
    [
        None,                                               # the shipped example
        json.dumps(ELL),
        shapely.to_geojson(shapely.Polygon(ELL)),
        json.dumps({"type": "Feature", "properties": {},
                    "geometry": json.loads(shapely.to_geojson(shapely.Polygon(ELL)))}),
        shapely.Polygon(ELL).wkt,
        shapely.Polygon(ELL).wkb,
    ],
    ids=["body-ell.json", "list", "geojson", "feature", "wkt", "wkb"],
)
def test_collide_given_a_body_file_says_it_is_not_a_scene(tmp_path, capsys, content):
    path = (str(EXAMPLES / "body-ell.json") if content is None
            else _write(tmp_path, "ell.json", content))
    assert main(["collide", path]) == 2
    line = _error(capsys)
    assert line.startswith(f"polycontact collide: error: {path}: this is a body file, not a "
                           "scene: collide takes a scene (")
    assert '"t_max"' in line and '"bodies"' in line and "collide --help" in line
    assert "unknown key" not in line


@pytest.mark.parametrize(
    ("doc", "message"),
    [
        ({"t_max": 1, "bodies": [{"vertices": ELL}, {"vertices": ELL}], "colour": 1},
         "colour: unknown key"),
        ({"bodies": [{"vertices": ELL}, {"vertices": ELL}]}, "t_max: missing"),
        ({"t_max": 1, "bodies": [{"vertices": ELL}]}, "expected at least two bodies"),
    ],
)
def test_a_broken_scene_keeps_its_own_message(tmp_path, capsys, doc, message):
    path = _write(tmp_path, "scene.json", json.dumps(doc))
    assert main(["collide", path]) == 2
    line = _error(capsys)
    assert message in line and "body file" not in line


def test_collide_help_describes_the_scene_format(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["collide", "--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    for key in ('"t_max"', '"time_tolerance"', '"bodies"', '"name"', '"vertices"', '"holes"',
                '"velocity"', '"acceleration"', '"angular_velocity"',
                '"angular_acceleration"', '"angular_velocity_deg"',
                '"angular_acceleration_deg"'):
        assert key in text, key
    for words in ("radians per time", "length per time", "any unit", "example:",
                  "paper-case-1"):
        assert words in text, words


def test_the_example_of_collide_help_runs_as_it_says(tmp_path, capsys):
    example = collide.SCENE_FORMAT.split("example:\n", 1)[1].split("\n  answers", 1)[0]
    path = _write(tmp_path, "scene.json", example)
    assert main(["collide", path]) == 0
    out = capsys.readouterr().out
    assert float(re.search(r"collision at t = (\S+)", out).group(1)) == pytest.approx(
        1.0, abs=1e-3)
    assert 'answers "collision at t = 1.00..."' in collide.SCENE_FORMAT


def test_the_example_that_needs_repair_says_so_in_its_description():
    description = json.loads((EXAMPLES / "paper-case-2.json").read_text())["description"]
    assert description.startswith("Run with --repair: ")
    assert "not simple" in description and "make_valid" in description


@pytest.mark.parametrize("command", [["collide", str(EXAMPLES / "body-ell.json")],
                                     ["classify", "missing-a.json", FRAME],
                                     ["nfp", "missing-a.json", FRAME]])
def test_a_wrong_input_is_refused_before_any_compiling(tmp_path, command):
    # a first run (an empty compile cache): the error comes at once, nothing compiles
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(NUMBA_CACHE_DIR=str(tmp_path), POLYCONTACT_NOTICE_AFTER="inf")
    out = subprocess.run([sys.executable, "-m", "polycontact", *command], capture_output=True,
                         text=True, env=env, timeout=600)
    assert out.returncode == 2 and out.stdout == ""
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and "error" in lines[0] and "compiling" not in lines[0], out.stderr
