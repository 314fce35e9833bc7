"""Private compiled kernels: plain functions over float64 arrays and scalars.

Conventions shared by every kernel:

- A shape is packed as ``xy`` (float64, shape (V, 2)) holding every loop's vertices one
  loop after another (outer loop first, counter-clockwise; holes after it, clockwise),
  and ``starts`` (int64, shape (L + 1,)) with loop ``k`` occupying rows
  ``starts[k]:starts[k + 1]``. Edge ``e`` of loop ``k`` joins its vertex ``e`` and vertex
  ``(e + 1) % n_k``.
- Tolerances and limits arrive as arguments, never from module globals.
- Kernels are compiled on first use (``cache=True``), never at import; the cache
  locator (:mod:`.cache`) and the notice a first compile gives (:mod:`.jit`) are
  installed here, before any kernel module is loaded.
- Kernels are decorated with :func:`.jit.njit` (Numba's ``njit`` with the same
  options), which compiles one specialisation per kernel for its callers' argument
  types: read-only and writable arrays, constants and variables.
- This package imports NumPy, Numba and itself only (and ``platformdirs`` for the
  cache's directory). A kernel reports what it finds (a status code, NaNs); the public
  function that called it raises the error. (A kernel raises only when its caller gave
  it a scratch buffer too short.)
"""

from .cache import install_cache_locator
from .jit import install_compile_notice

install_cache_locator()
install_compile_notice()
