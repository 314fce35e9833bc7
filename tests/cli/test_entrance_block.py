"""``polycontact entrance-block``: summary, JSON, the figure, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from polycontact.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ELL = str(EXAMPLES / "body-ell.json")
FRAME = str(EXAMPLES / "body-frame.json")


@pytest.mark.parametrize(("method", "n_edge"), [("swept", 10), ("pairs", 60)])
def test_json_summary_both_methods(capsys, method, n_edge):
    assert main(["entrance-block", ELL, FRAME, "--method", method, "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["method"] == method
    assert rep["components"] == {"A2-B0": 10, "A0-B2": 6, "A1-B1": n_edge}
    assert rep["reference"] == pytest.approx([1.1, 1.1])  # the ell's centroid
    # the 9 × 9 box of B ⊕ box(a0 − A), minus the 2 × 2 corner the reflected ell misses,
    # minus the 0.5 × 0.5 hole: where the ell floats in the frame's hole
    assert rep["area"] == pytest.approx(81 - 4 - 0.25)
    assert rep["relation"]["state"] == "contact"


def test_text_summary_and_reference(capsys):
    assert main(["entrance-block", ELL, FRAME, "--reference=0,0"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1] == "reference point a0: (0, 0)"
    assert out[2] == ("components: 10 E(A(2), B(0)) + 6 E(A(0), B(2)) + 10 E(A(1), B(1)) "
                      "= 26 (0 of zero width)")
    assert out[3].startswith("area of E(A, B): 76.75")
    assert out[4:6] == ["relation at a0:", "  state: contact"]


@pytest.mark.parametrize("reference", ["1.1,1.1", "5.35,1.35", "-3,0"])
def test_the_reference_moves_the_block_not_the_relation(capsys, reference):
    # a0 is a point of A's frame: another choice moves E(A, B) with it, so the area
    # and the relation at a0 (A where it stands) stay the same
    main(["entrance-block", ELL, FRAME, f"--reference={reference}", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rep["reference"] == [float(v) for v in reference.split(",")]
    assert rep["area"] == pytest.approx(76.75)
    assert rep["relation"]["state"] == "contact"


def test_plot_is_written(tmp_path, capsys):
    out = tmp_path / "eb.png"
    assert main(["entrance-block", ELL, FRAME, "--method", "pairs", "--plot", str(out)]) == 0
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


def test_unwritable_plot_is_one_line(tmp_path, capsys):
    out = tmp_path / "no-such-dir" / "eb.png"
    assert main(["entrance-block", ELL, FRAME, "--plot", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"polycontact entrance-block: error: {out}:")


def test_bad_file_is_one_line_naming_it(tmp_path, capsys):
    bad = tmp_path / "b.json"
    bad.write_text('{"vertices": [[0, 0], [1, 0], [1, 1]], "holes": [[[5, 5], [6, 5], [6, 6]]]}')
    assert main(["entrance-block", ELL, str(bad)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (f"polycontact entrance-block: error: {bad}: hole 0 lies outside "
                            "the outer loop (its vertex 0 is at (5, 5))\n")


@pytest.mark.parametrize("value", ["1", "1,2,3", "a,b", "nan,0"])
def test_bad_reference_is_a_usage_error(capsys, value):
    with pytest.raises(SystemExit) as exc:
        main(["entrance-block", ELL, FRAME, f"--reference={value}"])
    assert exc.value.code == 2
    assert "--reference" in capsys.readouterr().err
