"""The first run: where the compiled kernels go, and the notice a cold cache gives.

Each test runs polycontact in a subprocess with an empty cache of its own, so nothing
here depends on what the rest of the suite has compiled.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import polycontact
from polycontact import compiling

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PACKAGE = Path(polycontact.__file__).resolve().parent
#: The start of the notice of a compile.
NOTICE = "polycontact is compiling the kernels this call needs"


def _run(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    full = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    full.update(env)
    return subprocess.run(args, capture_output=True, text=True, env=full, timeout=600)


def test_cache_goes_to_the_user_cache_directory_not_site_packages(tmp_path):
    code = (
        "import numpy as np\n"
        "from polycontact._kernels.advance import traversal_stack\n"
        "traversal_stack()\n"
        "from polycontact import compiling\n"
        "print(compiling.cache_directory())\n"
    )
    before = set(PACKAGE.rglob("*.nbi"))
    out = _run([sys.executable, "-c", code], {"XDG_CACHE_HOME": str(tmp_path)})
    assert out.returncode == 0, out.stderr
    where = Path(out.stdout.strip())
    assert where == tmp_path / "polycontact" / "numba"
    assert any(where.rglob("advance.traversal_stack*.nbi"))
    assert set(PACKAGE.rglob("*.nbi")) == before


def test_numba_cache_dir_overrides_the_location(tmp_path):
    out = _run(
        [sys.executable, "-c", "from polycontact import compiling; print(compiling.cache_directory())"],
        {"NUMBA_CACHE_DIR": str(tmp_path)},
    )
    assert Path(out.stdout.strip()) == tmp_path


@pytest.mark.slow
def test_cold_cache_notice_goes_to_stderr_and_json_stays_parseable(tmp_path):
    """A real first run: a fresh cache compiles the classification kernels the command
    runs (seconds to tens of seconds), says so once on stderr, and stdout is the JSON
    alone; the second run compiles nothing and says nothing."""
    out = _run(
        [sys.executable, "-m", "polycontact", "classify", str(EXAMPLES / "body-ell.json"),
         str(EXAMPLES / "body-frame.json"), "--json"],
        {"NUMBA_CACHE_DIR": str(tmp_path), "POLYCONTACT_NOTICE_AFTER": "inf"},
    )
    assert out.returncode == 0, out.stderr
    assert out.stderr.count(NOTICE) == 1, out.stderr
    assert "compiling" not in out.stdout
    assert json.loads(out.stdout)["state"] == "contact"
    again = _run(
        [sys.executable, "-m", "polycontact", "classify", str(EXAMPLES / "body-ell.json"),
         str(EXAMPLES / "body-frame.json"), "--json"],
        {"NUMBA_CACHE_DIR": str(tmp_path), "POLYCONTACT_NOTICE_AFTER": "inf"},
    )
    assert again.returncode == 0 and again.stderr == ""
    assert json.loads(again.stdout) == json.loads(out.stdout)


#: Two small kernels: compiling them is quick.
SMALL_KERNELS = (
    "from polycontact._kernels.advance import traversal_stack\n"
    "from polycontact._kernels.packs import scratch_floats\n"
    "traversal_stack()\n"
    "scratch_floats(24)\n"
)


def test_a_call_that_compiles_says_so_once_and_logging_silences_it(tmp_path):
    out = _run([sys.executable, "-c", SMALL_KERNELS], {"NUMBA_CACHE_DIR": str(tmp_path / "a")})
    assert out.returncode == 0, out.stderr
    assert out.stderr.count(NOTICE) == 1, out.stderr
    assert str(tmp_path / "a") in out.stderr  # where the compiled kernels go
    silenced = _run([sys.executable, "-c", "import logging\n"
                     "logging.getLogger('polycontact').setLevel(logging.ERROR)\n"
                     + SMALL_KERNELS], {"NUMBA_CACHE_DIR": str(tmp_path / "b")})
    assert silenced.returncode == 0 and silenced.stderr == "", silenced.stderr
    # loaded from the cache: nothing to say
    again = _run([sys.executable, "-c", SMALL_KERNELS], {"NUMBA_CACHE_DIR": str(tmp_path / "a")})
    assert again.returncode == 0 and again.stderr == "", again.stderr


def test_installs_of_the_same_sources_in_two_places_share_the_compiled_kernels(tmp_path):
    # (as an editable install and a regular one of the same release do)
    import shutil

    code = "import polycontact\nprint(polycontact.__file__)\n" + SMALL_KERNELS
    cache = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    for k, place in enumerate(("first", "second")):
        shutil.copytree(PACKAGE, tmp_path / place / "polycontact",
                        ignore=shutil.ignore_patterns("__pycache__"))
        out = _run([sys.executable, "-c", code], {**cache, "PYTHONPATH": str(tmp_path / place)})
        assert out.returncode == 0, out.stderr
        assert out.stdout.startswith(str(tmp_path / place))
        assert out.stderr.count(NOTICE) == (1 if k == 0 else 0), out.stderr


@pytest.mark.parametrize("processes", ["1", "2"])
def test_warmup_command_reports_every_family(tmp_path, processes):
    # Without the JIT the "compilation" is instant; the reporting is the same.
    out = _run([sys.executable, "-m", "polycontact", "warmup", "--processes", processes],
               {"NUMBA_CACHE_DIR": str(tmp_path), "NUMBA_DISABLE_JIT": "1"})
    assert out.returncode == 0, out.stderr
    for k, family in enumerate(compiling.FAMILIES, 1):
        assert f"[{k}/{len(compiling.FAMILIES)}] {family} ... " in out.stderr
    assert out.stdout.startswith("kernels ready in")


def test_warmup_processes_take_the_longest_families_first(monkeypatch):
    # every family has its compile cost, and the pool is given them longest first
    assert set(compiling._COMPILE_SECONDS) == set(compiling.FAMILIES)
    taken = []

    class Pool:
        def __init__(self, *args, **kwargs):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def submit(self, fn, family):
            import concurrent.futures

            taken.append(family)
            done = concurrent.futures.Future()
            done.set_result(0.0)
            return done

    import concurrent.futures

    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", Pool)
    seen = []
    compiling.warmup(list(compiling.FAMILIES), processes=2,
                     progress=lambda family, k, n, s: seen.append((family, k)))
    costs = [compiling._COMPILE_SECONDS[f] for f in taken]
    assert sorted(taken) == sorted(compiling.FAMILIES) and costs == sorted(costs, reverse=True)
    # each family keeps its number in the order given
    assert sorted(set(seen), key=lambda fk: fk[1]) == [
        (f, k) for k, f in enumerate(compiling.FAMILIES, 1)]


def test_warmup_workers_number_their_functions_apart_from_other_processes():
    # two processes that compile into one cache must not give one name to different
    # functions (numba/numba#10486): a worker's numbers start at its process id * 2**20
    code = ("import os\n"
            "from numba.core.bytecode import FunctionIdentity\n"
            "from polycontact import compiling\n"
            "compiling._worker_start()\n"
            "print(next(FunctionIdentity._unique_ids) - (os.getpid() << 20))\n")
    out = _run([sys.executable, "-c", code], {})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "0"


def test_warmup_refuses_a_number_of_processes_below_one():
    with pytest.raises(ValueError, match="processes: expected an int >= 1"):
        compiling.warmup(["classification"], processes=0)


@pytest.mark.slow
def test_a_family_warmed_up_alone_is_warm(tmp_path):
    # is_warm reads the cache index of the kernels each family lists: they must be the
    # kernels the family's own functions compile (an entry point renamed or no longer
    # called leaves is_warm False forever: every start announced a compile). Each family
    # is warmed up alone, the last listed first, so that its check does not rest on
    # what an earlier family compiled: "entrance block" named relate_state, which only
    # classify's first call used to compile, and after classify stopped compiling it
    # (it binds that kernel on the first pair too large for its scratch) neither family
    # was ever warm.
    out = _run([sys.executable, "-c",
                "from polycontact import compiling\n"
                "cold = []\n"
                "for f in reversed(list(compiling.FAMILIES)):\n"
                "    compiling.warmup([f])\n"
                "    cold += [] if compiling.is_warm([f]) else [f]\n"
                "print(cold)\n"],
               {"NUMBA_CACHE_DIR": str(tmp_path)})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_version():
    out = _run([sys.executable, "-m", "polycontact", "--version"], {})
    assert out.stdout.strip() == f"polycontact {polycontact.__version__}"


def test_warmup_refuses_an_unknown_family():
    with pytest.raises(ValueError, match="families: expected names from"):
        compiling.warmup(["classfication"])


def test_a_kernel_changed_in_another_module_gets_a_fresh_cache(tmp_path):
    # Numba checks only the file of the function it cached, but exact_query (in
    # impact.py) has overlap_intervals (in broad_phase.py) compiled into it: after a
    # change to broad_phase.py alone Numba loaded the old code. The cache's directory is
    # named after all the kernels' sources, so such a change lands in a fresh one.
    import shutil

    copy = tmp_path / "_kernels"
    shutil.copytree(PACKAGE / "_kernels", copy, ignore=shutil.ignore_patterns("__pycache__"))
    before = compiling.kernel_sources_fingerprint(copy)
    assert before == compiling.kernel_sources_fingerprint()
    target = copy / "broad_phase.py"
    target.write_text(target.read_text() + "\n# a change\n")
    assert compiling.kernel_sources_fingerprint(copy) != before
    # and the kernels' cache lives in the directory of the current sources
    code = (
        "from polycontact._kernels.advance import traversal_stack\n"
        "from polycontact import compiling\n"
        "traversal_stack()\n"
        "print(traversal_stack._cache._cache_path)\n"
        "print(compiling.kernel_sources_fingerprint())\n"
    )
    for env in ({"NUMBA_CACHE_DIR": str(tmp_path / "numba")}, {"XDG_CACHE_HOME": str(tmp_path)}):
        out = _run([sys.executable, "-c", code], env)
        assert out.returncode == 0, out.stderr
        path, fingerprint = out.stdout.split()
        assert Path(path).name.endswith("-" + fingerprint), path
        assert any(Path(path).glob("advance.traversal_stack*.nbi"))
