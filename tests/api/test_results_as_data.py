"""Results as data: ``to_dict()`` is JSON-ready and is what the CLI's
``--json`` prints; geometric results have ``__geo_interface__``; every result plots
itself into a matplotlib Axes."""

from __future__ import annotations

import json

import pytest
import shapely
import shapely.geometry

import polycontact as pc
from polycontact.cli import main

A = {"vertices": [[0, 0], [10, 0], [10, 10], [0, 10]],
     "holes": [[[2, 2], [2, 4], [4, 4], [4, 2]]]}
B = {"vertices": [[10, 2], [13, 2], [13, 5], [10, 5]],
     "holes": [[[11, 3], [11, 4], [12, 4], [12, 3]]]}
B_SEPARATE = {"vertices": [[11, 2], [14, 2], [14, 5], [11, 5]]}
B_PENETRATING = {"vertices": [[9, 2], [12, 2], [12, 5], [9, 5]]}


def _cli_json(capsys, *args: str) -> dict:
    assert main([*args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def _write(tmp_path, name: str, data: dict) -> str:
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return str(path)


def _round_trip(d: dict) -> dict:
    back = json.loads(json.dumps(d, allow_nan=False))
    assert back == d
    return back


@pytest.mark.parametrize("b", [B, B_SEPARATE, B_PENETRATING])
def test_relation_to_dict_is_the_cli_json(tmp_path, capsys, b):
    d = _round_trip(pc.classify(A, b).to_dict())
    assert d == _cli_json(capsys, "classify", _write(tmp_path, "a.json", A),
                          _write(tmp_path, "b.json", b))
    if d["state"] == "separate":
        assert d["features"] == [] and d["normal"] is None


def test_entrance_block_to_dict_is_the_cli_json(tmp_path, capsys):
    block = pc.entrance_block(A, B)
    d = _round_trip(block.to_dict())
    assert d == _cli_json(capsys, "entrance-block", _write(tmp_path, "a.json", A),
                          _write(tmp_path, "b.json", B))
    assert d["relation"] == pc.classify(A, B).to_dict()
    assert shapely.geometry.shape(block).equals(block.to_shapely())
    assert shapely.geometry.shape(d["region"]).equals(block.to_shapely())


def test_no_fit_polygon_to_dict_is_the_cli_json(tmp_path, capsys):
    nfp = pc.no_fit_polygon(A, B)
    d = _round_trip(nfp.to_dict())
    assert d == _cli_json(capsys, "nfp", _write(tmp_path, "a.json", A),
                          _write(tmp_path, "b.json", B))
    assert d["area"] == nfp.region.area > 0
    assert shapely.geometry.shape(nfp).equals(nfp.region)


def test_impact_to_dict_is_the_cli_json(tmp_path, capsys):
    scene = {"t_max": 5, "bodies": [{"name": "box", **A},
                                    {"name": "ring", **B_SEPARATE, "velocity": [-1, 0]}]}
    loaded = pc.load_scene(scene)
    i, j, impact = loaded.first_impact()
    d = _round_trip(impact.to_dict((loaded.bodies[i].name, loaded.bodies[j].name)))
    assert d == _cli_json(capsys, "collide", _write(tmp_path, "scene.json", scene))
    assert d["status"] == "hit" and d["pair"] == ["box", "ring"]
    assert {f["body"] for f in d["features"]} <= {"box", "ring"}


def test_contacts_to_dict_is_the_cli_json(tmp_path, capsys):
    layout = {"container": A, "placed": [{"item": 0, **B}, {"item": 1, **B_PENETRATING},
                                          {"item": 2, "vertices": [[5, 5], [6, 5], [6, 6]]}]}
    names = ["0 (0)", "1 (1)", "2 (2)"]
    world = pc.World(container=A)
    world.add_many([B, B_PENETRATING, [[5, 5], [6, 5], [6, 6]]], names=names)
    d = _round_trip(world.contacts().to_dict(names))
    assert d == _cli_json(capsys, "contacts", _write(tmp_path, "layout.json", layout))
    assert d["bodies"] == 3 and d["container"] is True
    assert [c["state"] for c in d["contacts"]] == ["penetrating"]


def _results() -> dict:
    scene = pc.load_scene({"t_max": 5, "bodies": [{"vertices": A["vertices"]},
                                                  {**B_SEPARATE, "velocity": [-1, 0]}]})
    world = pc.World(container=A)
    world.add(B)
    world.add(B_PENETRATING)
    return {"Relation": pc.classify(A, B), "Impact": scene.first_impact().impact,
            "EntranceBlock": pc.entrance_block(A, B), "NoFitPolygon": pc.no_fit_polygon(A, B),
            "Contacts": world.contacts()}


@pytest.mark.parametrize("kind", ["Relation", "Impact", "EntranceBlock", "NoFitPolygon",
                                  "Contacts"])
def test_every_result_plots_itself(kind):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.axes import Axes

    result = _results()[kind]
    _round_trip(result.to_dict())
    try:
        ax = result.plot()
        assert isinstance(ax, Axes) and ax.get_title()
        fig, mine = plt.subplots()
        assert result.plot(ax=mine) is mine
        assert mine.has_data()
    finally:
        plt.close("all")
