"""The datasets shipped with the package: each loads, is what it says, ships in the
wheel, and the command line reaches it by name."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

import polycontact as pc
from polycontact import datasets
from polycontact.cli import main as cli

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = Path(pc.__file__).resolve().parent


def test_every_kind_has_a_dataset():
    for kind in datasets.KINDS:
        assert datasets.names(kind)
        for name in datasets.names(kind):
            assert datasets.path(kind, name).is_file()


def test_every_instance_reads_and_has_its_published_layout():
    for name in datasets.names("esicup"):
        inst = datasets.instance(name)
        assert inst.name == name and len(inst.pieces) == len(inst.demand)
        assert name in datasets.names("layouts")


@pytest.mark.parametrize("name", datasets.names("layouts"))
def test_a_published_layout_is_feasible(name):
    world = datasets.layout(name)
    inst = datasets.instance(name)
    assert len(world) == sum(inst.demand)
    c = world.contacts()
    assert not (c.states == 2).any() and not (c.container_states == 2).any()


def test_the_shipped_scene_is_the_examples_one():
    shipped = json.loads(datasets.path("scenes", "paper-case-1").read_text())
    assert shipped == json.loads((ROOT / "examples" / "paper-case-1.json").read_text())
    assert [b.name for b in datasets.scene("paper-case-1").bodies] == ["red", "blue"]


def test_an_unknown_name_or_kind_lists_what_is_shipped():
    with pytest.raises(ValueError, match=r"name: no shipped layouts dataset 'swim' "
                                         r"\(shipped: jakobs1, shapes0\)"):
        datasets.layout("swim")
    with pytest.raises(ValueError, match="kind: expected one of esicup, layouts, scenes"):
        datasets.names("instances")


def test_a_file_of_that_name_comes_before_a_shipped_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert Path(datasets.locate("jakobs1", "esicup")) == datasets.path("esicup", "jakobs1")
    (tmp_path / "jakobs1").write_text("{}")
    assert datasets.locate("jakobs1", "esicup") == "jakobs1"
    assert datasets.locate("nothing.json", "esicup") == "nothing.json"


def test_every_shipped_file_is_package_data():
    """The wheel holds every file of the datasets: the globs of pyproject.toml's
    package-data match them all."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    globs = config["tool"]["setuptools"]["package-data"]["polycontact"]
    root = ROOT / "src" / "polycontact"
    data = {p for p in (root / "datasets").rglob("*")
            if p.is_file() and p.suffix not in (".py", ".pyc")}
    matched = {p for g in globs for p in root.glob(g)}
    assert data and data <= matched


def test_the_command_line_reaches_the_shipped_data_by_name(tmp_path, capsys):
    assert cli(["collide", "paper-case-1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["collides"] is True
    assert cli(["contacts", "shapes0", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["bodies"] == 43
    assert not [p for p in report["contacts"] if p["state"] == "penetrating"]
    assert cli(["nfp-table", "shapes0", "--out", str(tmp_path / "t"), "--no-progress",
                "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["entries"] == 16
