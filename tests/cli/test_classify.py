"""``polycontact classify``: text and JSON output, input formats, bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from polycontact.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ELL = str(EXAMPLES / "body-ell.json")
FRAME = str(EXAMPLES / "body-frame.json")


def _write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_text_output_names_state_distance_features_point_normal(capsys):
    assert main(["classify", ELL, FRAME]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == [
        "state: contact",
        "distance: 0",
        "features:",
        "  vertex 1 (loop 0) of a on edge 3 (loop 0) of b",
        "  vertex 2 (loop 0) of a on edge 3 (loop 0) of b",
        "point: (3, 0)",
        "normal: (1, 0)",
    ]


def test_json_output(capsys):
    assert main(["classify", ELL, FRAME, "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["state"] == "contact" and rep["distance"] == 0.0
    assert rep["features"][0] == {"body": "a", "loop": 0, "vertex": 1, "other_loop": 0,
                                  "edge": 3, "kind": "vertex-on-edge"}
    assert rep["point"] == [3.0, 0.0] and rep["normal"] == [1.0, 0.0]


def test_wkt_and_geojson_inputs_penetrating_with_an_edge_crossing(tmp_path, capsys):
    a = _write(tmp_path, "a.wkt", "POLYGON ((0 0, 2 0, 2 2, 0 2, 0 0))")
    b = _write(tmp_path, "b.geojson", json.dumps(
        {"type": "Feature", "properties": {},
         "geometry": {"type": "Polygon", "coordinates": [[[1, -1], [3, -1], [3, 1], [1, 1]]]}}))
    assert main(["classify", a, b, "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["state"] == "penetrating"
    assert rep["distance"] == pytest.approx(-1.0)
    crossing = [f for f in rep["features"] if f["kind"] == "edges-cross"]
    assert crossing and all(f["vertex"] is None and "own_edge" in f for f in crossing)
    assert main(["classify", a, b]) == 0
    text = capsys.readouterr().out
    assert "state: penetrating" in text and "of a crosses edge" in text


def test_tolerance_option(tmp_path, capsys):
    a = _write(tmp_path, "a.json", '{"vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]}')
    b = _write(tmp_path, "b.json", '{"vertices": [[1.000001, 0], [2, 0], [2, 1], [1.000001, 1]]}')
    main(["classify", a, b, "--json"])
    assert json.loads(capsys.readouterr().out)["state"] == "separate"
    main(["classify", a, b, "--json", "--tolerance", "1e-5"])
    rep = json.loads(capsys.readouterr().out)
    assert rep["state"] == "contact" and rep["tolerance"] == 1e-5


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "missing.json: cannot read (No such file or directory)"),
        ('{"vertices": [[0, 0], [1, 0]', "bad.json: not valid JSON"),
        ('{"vertices": [[0, 0], [2, 2], [2, 0], [0, 2]]}',
         "bad.json: outer loop: self-intersection at (1, 1) between edge 0 and edge 2"),
        ('{"vertices": [[0, 0], [1, 0], [0, 1]], "colour": "red"}',
         "bad.json: unknown key 'colour'"),
        ("POLYGON ((0 0, 1 0", "bad.json: not valid WKT"),
    ],
)
def test_bad_input_is_one_line_naming_the_file(tmp_path, capsys, content, message):
    path = str(tmp_path / "missing.json") if content is None else _write(tmp_path, "bad.json",
                                                                          content)
    assert main(["classify", path, FRAME]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("polycontact classify: error: ")
    assert message in lines[0] and path in lines[0]


def test_bad_tolerance_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["classify", ELL, FRAME, "--tolerance", "-1"])
    assert exc.value.code == 2
    assert "expected a number >= 0, got '-1'" in capsys.readouterr().err


def test_command_line_no_traceback(tmp_path):
    bad = _write(tmp_path, "bad.json", '{"vertices": "nope"}')
    run = subprocess.run([sys.executable, "-m", "polycontact", "classify", bad, FRAME],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2
    assert "Traceback" not in run.stderr and len(run.stderr.splitlines()) == 1
    assert run.stderr.startswith(f"polycontact classify: error: {bad}: ")


def test_separate_bodies_skip_the_feature_search(tmp_path, capsys, monkeypatch):
    # Before: the features (empty for separate bodies) were always searched: 55 s on two
    # 200 000-vertex bodies. The CLI now computes only what it prints.
    from polycontact._kernels import features as kfeat

    def no_features(*args):
        raise AssertionError("features searched for separate bodies")

    monkeypatch.setattr(kfeat, "features", no_features)
    a = _write(tmp_path, "a.json", '{"vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]}')
    b = _write(tmp_path, "b.json", '{"vertices": [[3, 0], [4, 0], [4, 1], [3, 1]]}')
    assert main(["classify", a, b, "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["state"] == "separate" and rep["features"] == []
    # (the witness is the midpoint of some closest pair)
    assert rep["distance"] == 2.0 and rep["point"][0] == 2.0 and 0.0 <= rep["point"][1] <= 1.0
    assert main(["classify", a, b]) == 0
    assert "features: none" in capsys.readouterr().out
