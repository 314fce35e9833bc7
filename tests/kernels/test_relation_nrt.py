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
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(NUMBA_CACHE_DIR=str(tmp_path),
               PYTHONPATH=os.pathsep.join([str(SRC), env.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True,
                         env=env, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split("\n")[:3] == ["1", "[5, 5, 5, 5, 5]", "True"]
