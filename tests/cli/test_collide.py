"""``polycontact collide``: text and JSON output, plots, one-line errors with status 2."""

import json
import re

import pytest

from polycontact import cli, compiling


@pytest.fixture
def run(monkeypatch, capsys):
    # only this subcommand: the test does not depend on the other subcommands' modules
    monkeypatch.setattr(cli, "_SUBCOMMANDS", ("collide",))
    # a cold cache adds the first-run notice to stderr (tested in test_compiling.py)
    compiling.warmup(["classification", "time of impact", "many moving bodies"])

    def _run(*argv):
        code = cli.main(["collide", *map(str, argv)])
        out, err = capsys.readouterr()
        return code, out, err

    return _run


def scene_file(tmp_path, data):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    return path


SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]


def test_json_output_has_every_key(run):
    code, out, err = run("examples/paper-case-1.json", "--json")
    assert code == 0 and err == ""
    rep = json.loads(out)
    assert {"collides", "time", "first_contact", "state", "features", "point", "normal",
            "method", "broad_phase", "pair", "status"} <= set(rep)
    assert rep["collides"] is True and rep["method"] == "exact"
    assert rep["time"] == pytest.approx(7.98475, abs=1e-4)
    assert rep["pair"] == ["red", "blue"] and rep["state"] == "penetrating"
    f = rep["features"][0]
    assert {"body", "vertex", "loop", "other_body", "edge"} <= set(f)
    assert {f["body"], f["other_body"]} == {"red", "blue"}
    assert rep["broad_phase"][0][0] == pytest.approx(6.1468, abs=1e-3)


def test_sampled_method_and_options(run):
    code, out, _ = run("examples/paper-case-1.json", "--json", "--method", "sampled",
                       "--samples", "10", "--time-tolerance", "1e-3")
    rep = json.loads(out)
    assert code == 0 and rep["method"] == "sampled"
    assert rep["time"] == pytest.approx(9.6965, abs=1e-3)


def _collision_time(out: str) -> float:
    return float(re.search(r"collision at t = (\S+)", out).group(1))


def test_case_2_needs_repair(run):
    code, out, err = run("examples/paper-case-2.json")
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert "self-intersection at (10.207" in err and "bodies[0].vertices" in err
    code, out, err = run("examples/paper-case-2.json", "--repair")
    assert code == 0 and "repaired red" in err
    assert _collision_time(out) == pytest.approx(2.48051, abs=1e-4)   # the oracle's


def test_text_output_and_plot(run, tmp_path):
    png = tmp_path / "impact.png"
    code, out, _ = run("examples/paper-case-1.json", "--plot", png)
    assert code == 0 and "pair: red and blue" in out
    assert _collision_time(out) == pytest.approx(7.98475, abs=1e-4)   # the oracle's
    assert png.stat().st_size > 10_000


def test_more_than_two_bodies_reports_the_pair(run, tmp_path):
    path = scene_file(tmp_path, {"t_max": 10, "bodies": [
        {"name": "p", "vertices": SQ, "velocity": [0, 1]},
        {"name": "q", "vertices": [[x + 5, y] for x, y in SQ], "velocity": [-1, 0]},
        {"name": "r", "vertices": [[x, y + 4] for x, y in SQ]},
    ]})
    rep = json.loads(run(path, "--json")[1])
    assert rep["pair"] == ["p", "r"] and rep["time"] == pytest.approx(3.0, abs=1e-4)


def test_no_collision(run, tmp_path):
    path = scene_file(tmp_path, {"t_max": 1, "bodies": [
        {"name": "p", "vertices": SQ}, {"name": "q", "vertices": [[x + 5, y] for x, y in SQ]}]})
    code, out, _ = run(path)
    assert code == 0 and "no collision (no-hit)" in out and "broad phase: none" in out


@pytest.mark.parametrize(
    "data, message",
    [
        ({"t_max": 1, "bodies": [{"vertices": SQ}]}, "at least two bodies"),
        ({"bodies": [{"vertices": SQ}, {"vertices": SQ}]}, "t_max: missing"),
        ({"t_max": 1, "bodies": [{"vertices": SQ, "velocity": "fast"}, {"vertices": SQ}]},
         "bodies[0].velocity"),
        ({"t_max": 1, "extra": 0, "bodies": [{"vertices": SQ}, {"vertices": SQ}]},
         "extra: unknown key"),
    ],
)
def test_bad_scene_is_one_line_and_status_2(run, tmp_path, data, message):
    code, out, err = run(scene_file(tmp_path, data))
    assert code == 2 and out == ""
    assert err.startswith("polycontact collide: error: ") and err.count("\n") == 1
    assert message in err


def test_bad_options_exit_2(run):
    with pytest.raises(SystemExit) as exc:
        run("examples/paper-case-1.json", "--samples", "1")
    assert exc.value.code == 2


THREE = {"t_max": 5, "bodies": [
    {"name": "a", "vertices": SQ, "velocity": [1, 0]},
    {"name": "b", "vertices": [[x + 3, y] for x, y in SQ]},
    {"name": "c", "vertices": [[x + 1.5, y + 1] for x, y in SQ]},
    {"name": "far", "vertices": [[x + 40, y] for x, y in SQ]},
]}


def test_all_lists_every_pair_that_meets_by_time(run, tmp_path):
    code, out, err = run(scene_file(tmp_path, THREE), "--all", "--json")
    assert code == 0
    events = json.loads(out)["events"]
    assert [e["pair"] for e in events] == [["a", "c"], ["a", "b"]]
    assert events[0]["status"] == "no-hit" and events[0]["state"] == "contact"
    assert events[1]["collides"] and events[1]["time"] == pytest.approx(2.0, abs=1e-4)
    code, out, _ = run(scene_file(tmp_path, THREE), "--all")
    assert code == 0 and out.startswith("2 pair(s) meet within t_max = 5")
    assert "pair: a and c" in out and "pair: a and b" in out


def test_three_bodies_first_impact_is_the_earliest_collision(run, tmp_path):
    code, out, _ = run(scene_file(tmp_path, THREE), "--json")
    rep = json.loads(out)
    assert code == 0 and rep["pair"] == ["a", "b"] and rep["collides"]
