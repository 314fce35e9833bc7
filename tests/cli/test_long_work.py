"""Long work says so: a command-line step still running after a delay prints one line on
stderr (and how long it took), never on stdout; ``classify --state-only`` skips the
distance, features, point and normal."""

from __future__ import annotations

import json
import threading
from pathlib import Path

import pytest

from polycontact.cli import _progress, main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ELL = str(EXAMPLES / "body-ell.json")
FRAME = str(EXAMPLES / "body-frame.json")


def _write(tmp_path: Path, name: str, doc) -> str:
    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return str(path)


def _no_lazy_parts(monkeypatch) -> None:
    """Make the distance, features and depth fail if they are called."""
    from polycontact import _depth
    from polycontact._kernels import distance, features

    def refuse(*args, **kwargs):
        raise AssertionError("computed although --state-only")

    for module, name in ((distance, "closest_pair"), (features, "features"),
                         (_depth, "penetration")):
        monkeypatch.setattr(module, name, refuse)


@pytest.mark.parametrize(
    ("b", "state"),
    [([[4, 0], [5, 0], [5, 1], [4, 1]], "separate"),
     ([[0.5, 0.5], [4, 0.5], [4, 4]], "penetrating"),
     ([[3, 0], [4, 0], [4, 1]], "contact")],
)
def test_state_only_prints_the_state_and_computes_nothing_else(tmp_path, capsys, monkeypatch,
                                                               b, state):
    a = _write(tmp_path, "a.json", [[0, 0], [3, 0], [3, 3], [0, 3]])
    b = _write(tmp_path, "b.json", b)
    _no_lazy_parts(monkeypatch)
    assert main(["classify", a, b, "--state-only"]) == 0
    assert capsys.readouterr().out == f"state: {state}\n"
    assert main(["classify", a, b, "--state-only", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep == {"state": state, "tolerance": rep["tolerance"]} and rep["tolerance"] > 0


def test_notices_go_to_stderr_and_name_the_step_and_its_size(capsys, monkeypatch):
    monkeypatch.setenv("POLYCONTACT_NOTICE_AFTER", "0")  # every step counts as long
    assert main(["classify", ELL, FRAME, "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["state"] == "contact"  # stdout stays the JSON alone
    lines = err.splitlines()
    steps = [line for line in lines if line.endswith(" ...")]
    assert steps == [
        f"polycontact: reading {ELL} (84 bytes) ...",
        f"polycontact: reading {FRAME} (143 bytes) ...",
        f"polycontact: classifying {ELL} (6 vertices) and {FRAME} (10 vertices) ...",
        f"polycontact: computing the features of {ELL} (6 vertices) and {FRAME} (10 vertices) "
        "(--state-only skips this) ...",
    ]
    done = [line for line in lines if not line.endswith(" ...")]
    assert len(done) == 4
    for step, end in zip(steps, done):
        assert end.startswith(step[:-4] + ": done in ") and end.endswith(" s")


def test_state_only_has_no_distance_step(capsys, monkeypatch):
    monkeypatch.setenv("POLYCONTACT_NOTICE_AFTER", "0")
    assert main(["classify", ELL, FRAME, "--state-only"]) == 0
    out, err = capsys.readouterr()
    assert out == "state: contact\n"
    assert "classifying" in err and "computing" not in err


@pytest.mark.parametrize(
    ("argv", "step"),
    [
        (["nfp", "examples/nfp-square.json", "examples/nfp-cavity.json"],
         "computing the no-fit polygon of A examples/nfp-square.json (4 vertices) and B "
         "examples/nfp-cavity.json (16 vertices)"),
        (["nfp", "examples/nfp-square.json", "examples/nfp-cavity.json", "--inner"],
         "computing the inner-fit polygon of A examples/nfp-square.json (4 vertices)"),
        (["entrance-block", ELL, FRAME], f"building the entrance block of A {ELL} "
                                         f"(6 vertices) to B {FRAME} (10 vertices)"),
        (["collide", "examples/paper-case-1.json"],
         "searching the first impact of 2 bodies (24 vertices) over [0, 20]"),
        (["collide", "examples/paper-case-1.json", "--all"],
         "searching every impact of 2 bodies (24 vertices) over [0, 20]"),
        (["contacts", "examples/layout.json"], "finding the contacts of 6 bodies"),
    ],
)
def test_every_long_step_of_every_command_says_so(capsys, monkeypatch, argv, step):
    monkeypatch.chdir(EXAMPLES.parent)
    monkeypatch.setenv("POLYCONTACT_NOTICE_AFTER", "0")
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert any(line.startswith(f"polycontact: {step}") and line.endswith(" ...")
               for line in err.splitlines()), err


def test_a_step_still_running_after_the_delay_says_so_while_it_runs(monkeypatch):
    said: list[str] = []
    noticed = threading.Event()

    def say(line: str) -> None:
        said.append(line)
        noticed.set()

    monkeypatch.setattr(_progress, "_say", say)
    monkeypatch.setenv("POLYCONTACT_NOTICE_AFTER", "0.01")
    with _progress.announced("a long step"):
        # the step ends only once the notice came (from the timer thread, while it runs)
        assert noticed.wait(timeout=600)
        assert said == ["a long step ..."]
    assert len(said) == 2 and said[1].startswith("a long step: done in ")


def test_a_step_that_ends_first_says_nothing(monkeypatch):
    said: list[str] = []
    monkeypatch.setattr(_progress, "_say", said.append)
    monkeypatch.setenv("POLYCONTACT_NOTICE_AFTER", "inf")
    with _progress.announced("a short step"):
        pass
    monkeypatch.setenv("POLYCONTACT_NOTICE_AFTER", "0")
    with pytest.raises(KeyError), _progress.announced("a failing step"):
        raise KeyError("x")
    assert said == ["a failing step ..."]  # no "done" for a step that failed


@pytest.mark.parametrize("value", ["soon", "-1", "nan", ""])
def test_a_bad_notice_delay_is_one_line_of_error(capsys, monkeypatch, value):
    monkeypatch.setenv("POLYCONTACT_NOTICE_AFTER", value)
    assert main(["classify", ELL, FRAME]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.splitlines() == [
        "polycontact classify: error: POLYCONTACT_NOTICE_AFTER: expected a number of seconds "
        f">= 0 (inf: no notices), got {value!r}"]
