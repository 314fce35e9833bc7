"""``--plot`` to a file matplotlib cannot write (``--plot x.txt``) is one line of
error naming the file, exit status 2, for every command, never a traceback."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from polycontact.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _layout(tmp_path: Path) -> str:
    sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    path = tmp_path / "layout.json"
    path.write_text(json.dumps({"bodies": [{"vertices": sq}, {"vertices": sq}]}))
    return str(path)


@pytest.mark.parametrize("command", ["entrance-block", "nfp", "collide", "contacts"])
@pytest.mark.parametrize("target", ["x.txt", "missing-dir/x.png"])
def test_plot_to_a_bad_file_is_one_line_not_a_traceback(tmp_path, capsys, command,
                                                                target):
    pytest.importorskip("matplotlib")
    out = str(tmp_path / target)
    files = {
        "entrance-block": [str(EXAMPLES / "body-ell.json"), str(EXAMPLES / "body-frame.json")],
        "nfp": [str(EXAMPLES / "body-ell.json"), str(EXAMPLES / "body-frame.json")],
        "collide": [str(EXAMPLES / "paper-case-2.json"), "--repair"],
        "contacts": [_layout(tmp_path)],
    }[command]
    assert main([command, *files, "--plot", out]) == 2
    err = capsys.readouterr().err.strip().splitlines()  # (collide --repair: notes first)
    errors = [line for line in err if ": error: " in line]
    assert errors == err[-1:] and "Traceback" not in "".join(err)
    assert errors[0].startswith(f"polycontact {command}: error: {out}: ")
