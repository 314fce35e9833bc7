"""Kernels compiled without Numba's reference counting (``_nrt=False``) and the helpers
they share with reference-counted kernels.

A helper called from an ``_nrt=False`` kernel before anything else compiled it is
compiled (and cached) without reference counting; if it returns new views, every
reference-counted caller that uses it afterwards (``state_scratch``, hence
``relate_state``, the World's kernels, ...) drops the views' buffer too early and frees
it while in use. Such helpers are inlined (``state_scratch_views``). The test runs in a
subprocess with an empty cache of its own, so the compile order is the one it sets.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import polycontact

SRC = Path(polycontact.__file__).resolve().parents[1]

CODE = """
import numpy as np
from polycontact import Shape
from polycontact._kernels import packs as kpack
from polycontact._kernels import relation as kr
a = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
b = a.moved((1.0, 0.5))
# the scratch-passing kernel first: its helpers are compiled from it
print(kr.relate_shapes_into(a._kernel, b._kernel, 1e-12))
views = kpack.state_scratch(8)
print([v.base.refcount for v in views])  # one reference per view
got = [kr.relate_state(*a.packed, *a.moved(d).packed, 1e-12)
       for d in ((1.0, 0.5), (0.5, 0.5), (3.0, 0.0)) for _ in range(50)]
print(got == [1] * 50 + [2] * 50 + [0] * 50)
"""


@pytest.mark.slow  # compiles from an empty cache
@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="compiled code only")
def test_scratch_views_compiled_first_from_a_kernel_without_reference_counting(tmp_path):
    assert _printed(CODE, tmp_path)[:3] == ["1", "[5, 5, 5, 5, 5]", "True"]


def _printed(code: str, cache: Path) -> list[str]:
    """The lines ``code`` prints, run in a subprocess compiling into the empty ``cache``."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(NUMBA_CACHE_DIR=str(cache),
               PYTHONPATH=os.pathsep.join([str(SRC), env.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.split("\n")


SWEEP_FIRST = """
import numpy as np
import polycontact as pc
from polycontact._kernels import broad_phase as kb
w = pc.World()
sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
w.add_many([sq, sq, sq], [(0.5, 0.5), (2.0, 0.5), (0.5, 5.0)])
# the swept search first: the broad phase and the search are compiled from it
s = w.sweep(1.0, [(1.0, 0.0), (0.0, 0.0), (0.0, 0.0)])
print(s.pairs.tolist(), [round(t, 4) for t in s.times.tolist()])
ca, cb = np.array([0.0, 0.0]), np.array([3.0, 0.0])
ma, mb = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]), np.zeros(6)
got = [kb.relative_motion(ca, ma, cb, mb) for _ in range(200)]
print(all(g.tolist() == [[-3.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 0.0]] for g in got),
      got[0].base is None or got[0].base.refcount == 1)
iv = [kb.overlap_intervals(ca, ma, 1.0, cb, mb, 1.0, 5.0, 0.0) for _ in range(200)]
print(all(i.round(9).tolist() == [[1.0, 5.0]] for i in iv))
b = pc.time_of_impact(sq, pc.Motion(velocity=(1, 0)), pc.Shape(sq).moved((3, 0)), pc.Motion(),
                      t_max=5)
print(b.status.value, round(b.time, 3))
"""


@pytest.mark.slow  # compiles from an empty cache
@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="compiled code only")
def test_broad_phase_compiled_first_from_the_swept_search_keeps_its_arrays(tmp_path):
    # the World's swept search runs without reference counting; the broad-phase helper
    # that returns its argument is inlined, so a reference-counted caller compiled
    # after it still owns the arrays it gets back
    assert _printed(SWEEP_FIRST, tmp_path)[:4] == ["[[0, 1]] [0.5]", "True True", "True",
                                                   "hit 2.0"]
