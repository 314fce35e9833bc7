"""Where Numba caches the compiled kernels: the cache locator, installed by this package
before any kernel is defined.

Numba's default would write the cache beside the installed sources
(``site-packages/polycontact``), where ``pip uninstall`` leaves it behind. The kernels'
cache goes in the per-user cache directory instead
(``platformdirs.user_cache_dir("polycontact")``, e.g. ``~/.cache/polycontact/numba`` on
Linux). Setting ``NUMBA_CACHE_DIR`` overrides this for every Numba library, as Numba
documents; other libraries' caches are never moved. Either way the kernels go in a
subdirectory named after a hash of all the kernels' sources
(:func:`kernel_sources_fingerprint`), since Numba tracks only each function's own file,
and not after where they are installed, so that every install of the same sources
(editable or not, any virtual environment) shares one compiled copy.

This module depends on the standard library and Numba alone (``platformdirs``, which
finds the per-user directory, is imported when a path is asked for).

Examples
--------
>>> cache_directory().is_absolute()
True
>>> len(kernel_sources_fingerprint())
16
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Any

__all__ = ["cache_directory", "kernel_sources_fingerprint", "install_cache_locator"]

#: The compiled layer's sources: the functions whose cache the locator claims.
_KERNELS = Path(__file__).resolve().parent


def cache_directory() -> Path:
    """The directory that holds polycontact's compiled kernels.

    ``NUMBA_CACHE_DIR`` when it is set (Numba's own override), else the per-user cache
    directory of polycontact.
    """
    override = os.environ.get("NUMBA_CACHE_DIR")
    if override:
        return Path(override)
    import platformdirs

    return Path(platformdirs.user_cache_dir("polycontact")) / "numba"


def kernel_sources_fingerprint(directory: Path | None = None) -> str:
    """A hash of the sources of every kernel module (``directory``: the ``_kernels``
    package by default), part of the cache's path.

    Numba's cache checks only the file of the function it compiled, but a kernel's
    compiled code includes the kernels it calls from other modules: after one of
    those changes (an upgrade that keeps a file's size and time, a branch switched in
    a source checkout) Numba would load the old code. Any change to any kernel source
    changes this hash, hence the cache directory: the kernels are compiled afresh.
    """
    digest = hashlib.sha256()
    for path in sorted((directory or _KERNELS).glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def install_cache_locator() -> None:
    """Make Numba cache polycontact's kernels in :func:`cache_directory`, in a
    subdirectory named after the kernels' sources (:func:`kernel_sources_fingerprint`).

    Called by ``polycontact._kernels`` before any kernel is defined. A locator class is
    put first in Numba's list; it claims only functions whose source lies in this
    package. If this Numba has no such list, its default applies: the cache stays
    beside the sources and is checked file by file only (see
    :func:`kernel_sources_fingerprint`).
    """
    try:
        from numba.core import caching
    except ImportError:  # pragma: no cover - numba is a dependency
        return
    classes = getattr(getattr(caching, "CacheImpl", None), "_locator_classes", None)
    base = getattr(caching, "UserProvidedCacheLocator", None)
    if not isinstance(classes, list) or base is None:  # pragma: no cover - other Numba
        return
    if any(getattr(c, "_polycontact", False) for c in classes):
        return
    fingerprint = kernel_sources_fingerprint()

    class _Locator(base):  # type: ignore[misc, valid-type]
        _polycontact = True

        def __init__(self, py_func: Any, py_file: str) -> None:
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            # named after the sources, not where they are installed: an editable
            # install and a regular one of the same sources share the compiled kernels
            self._cache_path = str(cache_directory() / f"kernels-{fingerprint}")

        @classmethod
        def from_function(cls, py_func: Any, py_file: str) -> Any:
            if not Path(py_file).resolve().is_relative_to(_KERNELS):
                return None
            locator = cls(py_func, py_file)
            try:
                locator.ensure_cache_path()
            except OSError:
                return None  # not writable: Numba's next locator decides
            return locator

    classes.insert(0, _Locator)
