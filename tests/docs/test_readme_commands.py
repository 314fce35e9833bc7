"""The README's shell commands run from a fresh clone, as a reader would type them.

Every ``polycontact …`` and ``python examples/…`` command of the README's ``bash`` and
``console`` blocks runs in a temporary directory holding a copy of ``examples/`` (what
a fresh clone has), against the package under test, and exits 0; where a ``console``
block shows a command's output, the command prints that output (durations aside); every
``--plot`` file is written. The steps the suite cannot run inside itself (making the
environment, installing, running the suite, building the documentation) are named in
``NOT_RUN``; any other command fails the test, so the README cannot grow a command
that nothing runs.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import polycontact

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"

#: Commands of the README that this test does not run, and why: the environment and
#: the install are the ones the suite runs in; the suite and the documentation build
#: are run by CI itself.
NOT_RUN = ("python3 -m venv ", ". .venv/bin/activate", "pip install ", "python -m pytest",
           "python -m sphinx ")

#: A duration printed by a command ("in 1.7 s", "1.05 s"): it varies from run to run.
DURATION = re.compile(r"\b\d+(\.\d+)? s\b")


def readme_commands(text: str) -> list[tuple[str, str | None]]:
    """(command, expected stdout or None) for every command of the README's shell
    blocks, in order; ``a && b`` gives two commands, the output going with the last."""
    commands: list[tuple[str, str | None]] = []
    for lang, body in re.findall(r"```(bash|console)\n(.*?)```", text, flags=re.S):
        if lang == "bash":
            for line in body.splitlines():
                words = shlex.split(line, comments=True)
                commands += [(" ".join(part), None) for part in _split_and(words) if part]
            continue
        for chunk in re.split(r"^\$ ", body, flags=re.M)[1:]:
            line, _, output = chunk.partition("\n")
            parts = [p for p in _split_and(shlex.split(line, comments=True)) if p]
            commands += [(" ".join(p), None) for p in parts[:-1]]
            commands.append((" ".join(parts[-1]), output))
    return commands


def _split_and(words: list[str]) -> list[list[str]]:
    parts: list[list[str]] = [[]]
    for w in words:
        if w == "&&":
            parts.append([])
        else:
            parts[-1].append(w)
    return parts


COMMANDS = readme_commands(README.read_text())
RUN = [(c, out) for c, out in COMMANDS if not c.startswith(NOT_RUN)]


def test_the_readme_starts_with_the_main_job_and_the_tests():
    bash = re.findall(r"```bash\n(.*?)```", README.read_text(), flags=re.S)
    assert "polycontact collide examples/paper-case-1.json" in bash[0]
    assert "python -m pytest" in bash[1]


def test_the_readme_test_command_is_what_ci_runs():
    bash = re.findall(r"```bash\n(.*?)```", README.read_text(), flags=re.S)
    command = bash[1].strip()
    ci = (ROOT / ".ci" / "run").read_text().replace("pip install -q ", "pip install ")
    assert command in ci


def test_every_readme_command_is_run_or_named():
    assert len(RUN) >= 8
    for command, _ in RUN:
        assert command.startswith(("polycontact ", "python examples/")), (
            f"the README runs {command!r}, which this test does not know how to run")


def _argv(command: str) -> list[str]:
    words = shlex.split(command)
    if words[0] == "polycontact":
        return [sys.executable, "-m", "polycontact", *words[1:]]
    return [sys.executable, *words[1:]]


@pytest.mark.parametrize("command, expected", RUN, ids=[c for c, _ in RUN])
def test_readme_command(command, expected, tmp_path):
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    env = dict(os.environ, MPLBACKEND="Agg")
    package_parent = str(Path(polycontact.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([package_parent, *filter(None, [
        os.environ.get("PYTHONPATH")])])
    done = subprocess.run(_argv(command), cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, f"{command}\n{done.stderr}"
    if expected is not None:
        assert DURATION.sub("<t> s", done.stdout).rstrip() == \
            DURATION.sub("<t> s", expected).rstrip()
    words = shlex.split(command)
    for k, word in enumerate(words[:-1]):
        if word == "--plot":
            assert (tmp_path / words[k + 1]).stat().st_size > 0
