"""Every subcommand fed a malformed file or option exits with status 2 and one line on
stderr that says what is wrong, never a traceback: integers beyond float64, JSON nested
deeper than any polycontact file, a motion that fails the reach check, a reference too
far for float64, repeated orientations, an output path that is a file or cannot be
written, and ``--plot`` without matplotlib."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from polycontact.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
HUGE = 10**400
DEEP = "[" * 100_000 + "]" * 100_000
NESTED = '{"vertices": ' + "[" * 40 + "]" * 40 + "}"


def _write(path: Path, doc) -> str:
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    return str(path)


def _scene(**body0) -> dict:
    return {"t_max": 5, "bodies": [{"name": "a", "vertices": SQUARE, **body0},
                                   {"name": "b", "vertices": [[3, 0], [4, 0], [4, 1], [3, 1]]}]}


def _instance(items=None, height=6) -> dict:
    items = items or [{"id": 0, "demand": 1, "allowed_orientations": [0, 90],
                       "shape": {"type": "simple_polygon", "data": SQUARE}}]
    return {"name": "tiny", "strip_height": height, "items": items}


def _piece(angles) -> list:
    return [{"id": 0, "demand": 1, "allowed_orientations": angles,
             "shape": {"type": "simple_polygon", "data": SQUARE}}]


#: name -> (files to write {name: content}, argv with {name} placeholders, a word the
#: error must hold)
CASES = {
    "classify: huge integer vertex": (
        {"a.json": {"vertices": [[HUGE, 0], [1, 0], [1, 1]]}}, ["classify", "{a.json}",
                                                               "{square}"], "a.json"),
    "classify: deeply nested body": ({"a.json": '{"vertices": ' + DEEP + "}"},
                                     ["classify", "{a.json}", "{square}"], "nested"),
    "classify: deeply nested text": ({"a.json": DEEP}, ["classify", "{a.json}", "{square}"],
                                     "nested"),
    "classify: nested body": ({"a.json": NESTED}, ["classify", "{a.json}", "{square}"],
                              "nested"),
    "classify: 5000-digit integer": (
        {"a.json": '{"vertices": [[1' + "0" * 5000 + ", 0], [1, 0], [1, 1]]}"},
        ["classify", "{a.json}", "{square}"], "a.json"),
    "collide: huge t_max": ({"s.json": {**_scene(), "t_max": HUGE}}, ["collide", "{s.json}"],
                            "t_max"),
    "collide: huge velocity": ({"s.json": _scene(velocity=[HUGE, 0])},
                               ["collide", "{s.json}"], "velocity"),
    "collide: huge vertex": ({"s.json": _scene(vertices=[[HUGE, 0], [1, 0], [1, 1]])},
                             ["collide", "{s.json}"], "vertices"),
    "collide: deeply nested": ({"s.json": DEEP}, ["collide", "{s.json}"], "nested"),
    "collide: reach check": ({"s.json": _scene(angular_velocity=1e300)},
                             ["collide", "{s.json}"], "bodies[0]"),
    "collide: reach over t_max": ({"s.json": {**_scene(angular_velocity=1e60), "t_max": 1e50}},
                                  ["collide", "{s.json}"], "bodies[0]"),
    "collide: --all reach check": ({"s.json": _scene(velocity=[1e300, 0])},
                                   ["collide", "{s.json}", "--all"], "bodies[0]"),
    "contacts: deeply nested": ({"l.json": DEEP}, ["contacts", "{l.json}"], "nested"),
    "contacts: huge vertex": (
        {"l.json": {"bodies": [{"vertices": [[HUGE, 0], [1, 0], [1, 1]]}]}},
        ["contacts", "{l.json}"], "body 0"),
    "entrance-block: nested": ({"a.json": NESTED}, ["entrance-block", "{a.json}", "{square}"],
                               "nested"),
    "entrance-block: far reference": ({}, ["entrance-block", "{square}", "{square}",
                                           "--reference=1e200,0"], "reference"),
    "nfp: reference too far": ({}, ["nfp", "{square}", "{square}", "--reference=1e15,0"],
                               "reference"),
    "nfp: deeply nested": ({"a.json": '{"vertices": ' + DEEP + "}"},
                           ["nfp", "{a.json}", "{square}"], "nested"),
    "nfp-table: huge strip height": ({"i.json": _instance(height=HUGE)},
                                     ["nfp-table", "{i.json}", "--out", "{out}"],
                                     "strip_height"),
    "nfp-table: huge orientation": ({"i.json": _instance(_piece([0, HUGE]))},
                                    ["nfp-table", "{i.json}", "--out", "{out}"],
                                    "allowed_orientations"),
    "nfp-table: deeply nested": ({"i.json": DEEP}, ["nfp-table", "{i.json}", "--out", "{out}"],
                                 "nested"),
    "nfp-table: orientation repeated modulo 360": (
        {"i.json": _instance(_piece([0, 360]))}, ["nfp-table", "{i.json}", "--out", "{out}"],
        "repeated"),
    "nfp-table: --orientations repeated": (
        {"i.json": _instance()}, ["nfp-table", "{i.json}", "--out", "{out}",
                                  "--orientations", "0", "0"], "repeated"),
    "nfp-table: --out is a file": ({"i.json": _instance(), "f.txt": "x"},
                                   ["nfp-table", "{i.json}", "--out", "{f.txt}"], "f.txt"),
    "nfp-table: --out below a file": ({"i.json": _instance(), "f.txt": "x"},
                                      ["nfp-table", "{i.json}", "--out", "{f.txt}/table"],
                                      "f.txt"),
}


def _run(tmp_path: Path, capsys, files: dict, argv: list[str]) -> tuple[int, str, str]:
    names = {"square": str(EXAMPLES / "nfp-square.json"), "out": str(tmp_path / "out")}
    for name, content in files.items():
        names[name] = _write(tmp_path / name, content)
    for name, value in names.items():
        argv = [a.replace("{" + name + "}", value) for a in argv]
    code = main(argv)
    got = capsys.readouterr()
    return code, got.out, got.err


def _one_line(err: str, command: str) -> str:
    lines = [line for line in err.splitlines()
             if not line.startswith("polycontact is compiling")]  # a cold first run
    assert len(lines) == 1 and len(lines[0]) < 1000, err[:2000]
    assert lines[0].startswith(f"polycontact {command}: error: "), err
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.parametrize("case", list(CASES))
def test_every_subcommand_refuses_a_malformed_input_in_one_line(tmp_path, capsys, case):
    files, argv, word = CASES[case]
    code, _, err = _run(tmp_path, capsys, files, argv)
    assert code == 2, err
    assert word in _one_line(err, argv[0])


PLOTS = {
    "classify": None,
    "collide": ["collide", str(EXAMPLES / "paper-case-1.json")],
    "contacts": ["contacts", "{l.json}"],
    "entrance-block": ["entrance-block", str(EXAMPLES / "body-ell.json"),
                       str(EXAMPLES / "body-frame.json")],
    "nfp": ["nfp", "{square}", str(EXAMPLES / "nfp-slot.json")],
}


@pytest.mark.parametrize("command", [c for c, argv in PLOTS.items() if argv])
def test_plot_without_matplotlib_says_how_to_install_it(tmp_path, capsys, monkeypatch,
                                                        command):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as after a plain `pip install .`
    files = {"l.json": {"bodies": [{"vertices": SQUARE}]}}
    code, out, err = _run(tmp_path, capsys, files, [*PLOTS[command], "--plot",
                                                    str(tmp_path / "x.png")])
    assert code == 2 and out == ""  # refused before anything is computed
    assert _one_line(err, command).endswith(
        "--plot needs matplotlib: pip install 'polycontact[plot]'")


def test_a_read_only_cache_that_holds_every_entry_is_read(tmp_path, capsys, monkeypatch):
    inst = _write(tmp_path / "i.json", _instance())
    out = str(tmp_path / "out")
    assert main(["nfp-table", inst, "--out", out, "--no-progress", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    from polycontact import nfp_tables

    def refuse(path: Path, data: bytes) -> None:
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(nfp_tables, "_atomic_write", refuse)
    assert main(["nfp-table", inst, "--out", out, "--no-progress", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["loaded"] == first["computed"] and again["computed"] == 0
    # a read-only cache that lacks entries: one line
    assert main(["nfp-table", inst, "--out", out, "--no-progress",
                 "--orientations", "0", "45"]) == 2
    assert "Permission denied" in _one_line(capsys.readouterr().err, "nfp-table")


def test_every_name_the_examples_import_from_polycontact_exists():
    # examples/nest_esicup.py --plot imported names polycontact.cli.contacts no longer had
    import ast
    import importlib

    for path in EXAMPLES.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("polycontact"):
                module = importlib.import_module(node.module)
                for alias in node.names:
                    assert hasattr(module, alias.name), (path.name, node.module, alias.name)
