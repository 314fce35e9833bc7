"""The local worker processes of an NFP-table build end when their parent dies, killed
or not: none (nor the resource tracker they keep alive) is left behind; a script whose
top-level code builds a table (no ``if __name__ == "__main__":``) gets it on threads,
and is warned only where the build would have used processes."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import polycontact
from polycontact.limits import EAR_CLIPPING_MAX

SRC = str(Path(polycontact.__file__).resolve().parents[1])  # the code under test

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc (Linux)"),
]


def _processes() -> dict[int, tuple[int, str, str]]:
    """pid -> (parent pid, state, command line) of every process."""
    out = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        out[int(entry.name)] = (int(fields[1]), fields[0], cmd)
    return out


def _descendants(pid: int) -> dict[int, str]:
    procs = _processes()
    found: dict[int, str] = {}
    todo = [pid]
    while todo:
        parent = todo.pop()
        for p, (pp, _, cmd) in procs.items():
            if pp == parent and p not in found:
                found[p] = cmd
                todo.append(p)
    return found


def _alive(pids) -> list[int]:
    procs = _processes()
    return [p for p in pids if p in procs and procs[p][1] != "Z"]  # a zombie has ended


def _instance(path: Path) -> Path:
    """Enough pieces and orientations (518 400 entries) for a build of many seconds on
    two processes: it is still running when the parent is killed. The rings have more
    vertices than ear clipping takes (:data:`polycontact.limits.EAR_CLIPPING_MAX`): their
    entries go through ``no_fit_polygon``, which holds the GIL, so that the build takes
    the processes it is allowed."""
    rng = np.random.default_rng(3)
    items = []
    for k in range(20):
        n = EAR_CLIPPING_MAX + 6
        t = 2 * np.pi * np.arange(n) / n
        r = rng.uniform(0.5, 1.5, n)
        ring = np.c_[r * np.cos(t), r * np.sin(t)] * 10
        items.append({"id": k, "demand": 1, "allowed_orientations": list(range(0, 360, 10)),
                      "shape": {"type": "simple_polygon", "data": ring.tolist()}})
    path.write_text(json.dumps({"name": "long", "strip_height": 100, "items": items}))
    return path


def test_killing_a_table_build_leaves_no_worker_alive(tmp_path):
    inst = _instance(tmp_path / "long.json")
    build = subprocess.Popen(
        [sys.executable, "-m", "polycontact", "nfp-table", str(inst), "--out",
         str(tmp_path / "out"), "--workers", "2", "--no-progress"],
        env={**os.environ, "PYTHONPATH": SRC}, stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL)
    children: dict[int, str] = {}
    try:
        deadline = time.monotonic() + 300
        workers: list[int] = []
        while time.monotonic() < deadline and build.poll() is None:
            children = _descendants(build.pid)
            workers = [p for p, cmd in children.items() if "spawn_main" in cmd]
            if len(workers) == 2 and list((tmp_path / "out" / "shards").glob("*.json")):
                break  # both workers started, and at work
            time.sleep(0.2)
        assert build.poll() is None and len(workers) == 2, (build.poll(), children)
        os.kill(build.pid, signal.SIGKILL)
        build.wait()
        time.sleep(10)
        assert _alive(children) == [], {p: children[p] for p in _alive(children)}
    finally:
        if build.poll() is None:
            build.kill()
            build.wait()
        for pid in _alive(children):  # (only when the test failed: ours to end)
            os.kill(pid, signal.SIGKILL)


_BUILD = """
import warnings

import shapely

import polycontact as pc
from polycontact import nfp_tables

sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
ell = pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
# a square frame: its entries, first, hold the GIL (no_fit_polygon)
frame = pc.Shape([(0, 0), (3, 0), (3, 3), (0, 3)], [[(1, 1), (1, 2), (2, 2), (2, 1)]])


def build(pieces=(frame, sq, ell)):
    nfp_tables.PROCESS_START = 1e-9  # processes pay wherever the work holds the GIL
    pools = []
    start = nfp_tables._run_processes
    nfp_tables._run_processes = lambda n, *args: (pools.append(n), start(n, *args))[1]
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        table = pc.nfp_table(pieces, [0, 90], progress=False, workers=2, chunk_size=2)
    one = pc.nfp_table(pieces, [0, 90], progress=False, workers=1)
    same = all(shapely.to_wkb(table[k].region) == shapely.to_wkb(one[k].region)
               for k in one)
    print("same" if same and len(table) == (2 * len(pieces)) ** 2 else "differ")
    print("process pools:", pools)
    for w in seen:
        print("warning:", w.category.__name__, w.message)
"""


def _run_script(tmp_path: Path, text: str) -> subprocess.CompletedProcess[str]:
    script = tmp_path / "build_table.py"
    script.write_text(text)
    return subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=600, cwd=tmp_path, env={**os.environ, "PYTHONPATH": SRC})


def test_a_script_without_a_main_guard_builds_on_threads(tmp_path):
    # spawned processes would run the script's top-level call again: threads instead,
    # with one warning naming the fix, and the table of one process
    done = _run_script(tmp_path, _BUILD + "\nbuild()\n")
    assert done.returncode == 0, done.stderr
    assert "bootstrapping" not in done.stderr
    lines = done.stdout.splitlines()
    assert lines[:2] == ["same", "process pools: []"], done.stdout
    assert len(lines) == 3 and lines[2].startswith("warning: RuntimeWarning"), lines
    assert "runs on threads" in lines[2] and "__name__ == '__main__'" in lines[2]


def test_a_script_without_a_main_guard_is_not_warned_where_processes_cannot_pay(tmp_path):
    # pieces without holes run on threads whatever workers= allows: nothing to warn of
    done = _run_script(tmp_path, _BUILD + "\nbuild((sq, ell))\n")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["same", "process pools: []"], (done.stdout,
                                                                       done.stderr)


def test_a_script_with_a_main_guard_builds_on_processes(tmp_path):
    done = _run_script(tmp_path, _BUILD + "\nif __name__ == '__main__':\n    build()\n")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["same", "process pools: [2]"], (done.stdout,
                                                                          done.stderr)
