"""``polycontact nfp``: text, WKT and JSON output, the plot, the inner-fit polygon, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import shapely

from polycontact.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
DOVE_A = str(EXAMPLES / "nfp-dovetail-a.json")
DOVE_B = str(EXAMPLES / "nfp-dovetail-b.json")
SQUARE = str(EXAMPLES / "nfp-square.json")
SLOT = str(EXAMPLES / "nfp-slot.json")
CAVITY = str(EXAMPLES / "nfp-cavity.json")


def test_text_output_lists_exact_fits(capsys):
    assert main(["nfp", DOVE_A, DOVE_B, "--reference", "origin"]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "reference point of A: (0, 0)",
        "region: 1 polygon(s), area 29.2, 0 hole(s)",
        "exact fits: 1",
        "  (0, 0)",
        "slides: 0",
    ]


def test_wkt_output_has_region_then_slides(capsys):
    assert main(["nfp", SQUARE, SLOT, "--reference", "0,0", "--wkt"]) == 0
    region, slides = capsys.readouterr().out.splitlines()
    assert shapely.from_wkt(region).area == 33.0
    assert slides == "MULTILINESTRING ((1.5 1, 1.5 4))"


def test_json_output_and_centroid_reference(capsys):
    assert main(["nfp", SQUARE, CAVITY, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["reference"] == [0.75, 0.75]
    assert data["holes"] == 2
    assert shapely.geometry.shape(data["region"]).area == pytest.approx(data["area"])
    assert data["exact_fits"] == [] and data["slides"] == []


def test_plot_is_written(tmp_path, capsys):
    out = tmp_path / "nfp.png"
    assert main(["nfp", SQUARE, CAVITY, "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_inner_fit(capsys):
    assert main(["nfp", SQUARE, CAVITY, "--inner", "--reference", "origin", "--wkt"]) == 0
    geom = shapely.from_wkt(capsys.readouterr().out)
    assert geom.geom_type == "MultiPolygon" and len(geom.geoms) == 2
    assert shapely.intersects_xy(geom, 0.25, 4.0)
    assert not shapely.intersects_xy(geom, 4.0, 1.0)  # A would cover the floor's hole


@pytest.mark.parametrize(
    "argv,message",
    [
        (["nfp", "missing.json", SQUARE], "missing.json: cannot read"),
        (["nfp", SQUARE, CAVITY, "--plot", "/nonexistent/dir/x.png"], "cannot write the plot"),
    ],
)
def test_user_errors_are_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("polycontact nfp: error:") and message in err
    assert "\n" not in err


@pytest.mark.parametrize("reference", ["middle", "1,2,3", "nan,0", "1,x"])
def test_bad_reference_is_refused_by_argparse(reference, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["nfp", SQUARE, SLOT, "--reference", reference])
    assert exc.value.code == 2
    assert "--reference" in capsys.readouterr().err


def test_invalid_shape_file(tmp_path, capsys):
    bad = tmp_path / "bow.json"
    bad.write_text('{"vertices": [[0, 0], [1, 1], [1, 0], [0, 1]]}')
    assert main(["nfp", str(bad), SQUARE]) == 2
    assert "self-intersection" in capsys.readouterr().err
    assert main(["nfp", str(bad), SQUARE, "--repair"]) == 2
    assert "cannot repair" in capsys.readouterr().err
    spike = tmp_path / "spike.json"
    spike.write_text('{"vertices": [[0, 0], [2, 0], [2, 2], [1, 2], [1, 3], [1, 2], [0, 2]]}')
    assert main(["nfp", str(spike), SQUARE]) == 2
    assert "spike" in capsys.readouterr().err
    assert main(["nfp", str(spike), SQUARE, "--repair"]) == 0


def test_inner_fit_prints_a_summary_like_nfp(capsys):
    assert main(["nfp", SQUARE, CAVITY, "--inner", "--reference", "origin"]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "reference point of A: (0, 0)",
        "inner-fit region: 2 polygon(s), area 17, 0 hole(s)",
        "exact fits: 0",
        "slides: 0",
    ]
    assert main(["nfp", SQUARE, SLOT, "--inner", "--reference", "origin"]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "reference point of A: (0, 0)",
        "inner-fit region: 0 polygon(s), area 0, 0 hole(s)",
        "exact fits: 0",
        "slides: 2",
        "  (0, 0) to (0, 2.5)",
        "  (3, 0) to (3, 2.5)",
    ]


def test_inner_fit_of_a_body_too_big_says_it_does_not_fit(capsys):
    assert main(["nfp", CAVITY, SQUARE, "--inner"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1:] == ["inner-fit region: 0 polygon(s), area 0, 0 hole(s)", "exact fits: 0",
                       "slides: 0", "A does not fit inside B"]


def test_inner_fit_json_holds_the_geometry_and_the_summary(capsys):
    assert main(["nfp", SQUARE, SLOT, "--inner", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["reference"] == [0.75, 0.75]
    assert shapely.geometry.shape(data["inner_fit"]).equals(
        shapely.MultiLineString([[(0.75, 0.75), (0.75, 3.25)], [(3.75, 0.75), (3.75, 3.25)]]))
    assert data["area"] == 0.0 and data["holes"] == 0 and data["exact_fits"] == []
    assert data["slides"] == [[[0.75, 0.75], [0.75, 3.25]], [[3.75, 0.75], [3.75, 3.25]]]


def test_inner_fit_plot_is_written(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "inner.png"
    assert main(["nfp", SQUARE, CAVITY, "--inner", "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert capsys.readouterr().out.startswith("reference point of A: (0.75, 0.75)\n")
