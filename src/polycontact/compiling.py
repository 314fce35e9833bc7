"""Compiling the kernels: whether the cache is warm, and warm-up.

polycontact's kernels are compiled by Numba on first use and cached on disk. A call
compiles only the kernels it runs, the first time they run on a machine (or after an
upgrade): a first call takes seconds to tens of seconds (about 40 s for the first time
of impact on a 2-core machine), and every run after it loads the compiled code in well
under a second.

**The notice.** The first compile of a process says so once, as a warning on the
``polycontact`` logger, shown on stderr when logging is not configured:
``polycontact is compiling the kernels this call needs, once: ...``.
``logging.getLogger("polycontact").setLevel(logging.ERROR)`` silences it. Kernels
loaded from the cache say nothing.

**Where the cache goes.** In the per-user cache directory (:func:`cache_directory`,
e.g. ``~/.cache/polycontact/numba`` on Linux; ``NUMBA_CACHE_DIR`` overrides it for
every Numba library), in a subdirectory named after a hash of all the kernels' sources
(:func:`kernel_sources_fingerprint`), shared by every install of the same sources
(editable or not); see :mod:`polycontact._kernels.cache`.

**Ahead of time.** :func:`warmup` compiles (or loads) every kernel family and reports
each stage to a callback, in this process or in several at once; ``polycontact
warmup`` does it from the command line, in one process per CPU, one line per family on
stderr.

This module is the top of the package: :func:`warmup` calls every public function.

Examples
--------
>>> from polycontact import compiling
>>> sorted(compiling.FAMILIES)  # doctest: +NORMALIZE_WHITESPACE
['classification', 'entrance block', 'many moving bodies', 'no-fit polygon',
 'no-fit polygon table', 'time of impact']
>>> compiling.cache_directory().is_absolute()
True
"""

from __future__ import annotations

import importlib
import itertools
import logging
import time
from collections.abc import Callable, Iterable
from typing import Any

from ._kernels.cache import cache_directory, kernel_sources_fingerprint

__all__ = ["FAMILIES", "cache_directory", "is_warm", "kernel_sources_fingerprint", "warmup"]

#: Kernel families, each with the kernels a warm cache must hold for it.
FAMILIES: dict[str, tuple[str, ...]] = {
    "classification": ("relation.relate_shapes_into", "relation.relate_state",
                       "rings.classify_raw", "depth.contact_depths"),
    "time of impact": ("impact.exact_call", "impact.sampled_query"),
    "no-fit polygon": ("nfp.ring_entrance", "nfp.entrance_packed", "fits.touching_contacts",
                       "fits.select_contacts"),
    "entrance block": ("validate.first_defect",),
    "many moving bodies": ("swept.slice_starts", "swept.boxes_into", "swept.sweep_strips",
                           "swept.impacts_chunk", "impact_batch.body_tables",
                           "impact_batch.suspect_bodies", "impact_batch.pair_bodies",
                           "impact_batch.ring_bodies", "impact_batch.pack_rings"),
    "no-fit polygon table": ("nfp_batch.nfp_pairs",),
}

#: About how many seconds of CPU each family's first compile takes (a 2-core development
#: machine, an empty cache). Only the order in which :func:`warmup`'s processes take the
#: families comes from it: the longest first, so that no long one starts last.
_COMPILE_SECONDS = {"no-fit polygon": 56.0, "classification": 44.0, "many moving bodies": 12.5,
                    "no-fit polygon table": 10.0, "time of impact": 2.5, "entrance block": 0.1}


def _dispatcher(name: str) -> Any:
    """The compiled kernel (a Numba dispatcher) ``"module.function"`` of ``_kernels``."""
    module, func = name.split(".")
    return getattr(importlib.import_module(f"._kernels.{module}", __package__), func)


def is_warm(families: Iterable[str] = FAMILIES) -> bool:
    """Whether the cache holds compiled code, for this Numba and these sources, for the
    kernels of ``families`` (all by default).

    Reads Numba's cache index of each kernel (a few small files); never compiles.
    Answers False when it cannot tell, so a cold start is announced rather than hidden.
    """
    try:
        for family in families:
            for name in FAMILIES[family]:
                cache = getattr(_dispatcher(name), "_cache", None)
                index = getattr(cache, "_cache_file", None)
                if index is None or not index._load_index():
                    return False
    except Exception:  # noqa: BLE001 - any doubt means "announce the compile"
        return False
    return True


def _run(family: str) -> None:
    """Call the public functions of one family on a tiny input (compiles its kernels)."""
    import numpy as np

    from .shape import Shape

    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    ell = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    # a slot as wide as the square: a slide, whose candidates are verified apart
    slot = [(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]
    if family == "classification":
        from .relation import classify, classify_many

        for d in ((2.0, 0.0), (1.0, 0.0), (0.5, 0.5)):
            r = classify(sq, sq + d)
            r.distance, r.features, r.point, r.normal  # noqa: B018 - computed on access
            rs = classify(Shape(sq), Shape(sq + d))
            rs.distance, rs.features  # noqa: B018
        classify_many(np.stack([sq, sq]), np.stack([sq + 2.0, sq + 0.5])).distances  # noqa: B018
        # more vertices than the state kernel's stack scratch holds: the kernel on the arrays
        t = np.linspace(0.0, 2.0 * np.pi, 300, endpoint=False)
        disk = Shape(np.c_[np.cos(t), np.sin(t)])
        # (and the depth of bodies too large for the contact segments: the convex sums)
        classify(disk, disk.moved((0.5, 0.0))).distance  # noqa: B018
        classify_many([disk], [disk.moved((0.5, 0.0))]).distances  # noqa: B018
    elif family == "time of impact":
        from .impact import time_of_impact
        from .motion import Motion

        for method in ("exact", "sampled"):
            hit = time_of_impact(Shape(sq), Motion(velocity=(1.0, 0.0)),
                                 Shape(sq + (3.0, 0.0)), Motion(), t_max=5.0, method=method)
            hit.features  # noqa: B018
    elif family == "no-fit polygon":
        from .nfp import inner_fit_polygon, no_fit_polygon

        no_fit_polygon(Shape(ell), Shape(sq)).region  # noqa: B018
        no_fit_polygon(Shape(sq), Shape(slot)).region  # noqa: B018
        inner_fit_polygon(Shape(sq), Shape(sq * 4.0))
        inner_fit_polygon(Shape(sq), Shape(sq))  # an exact fit
    elif family == "no-fit polygon table":
        from .nfp_tables import nfp_table

        nfp_table([Shape(ell), Shape(slot)], progress=False, threads=1)  # the batch kernel
    elif family == "entrance block":
        from .entrance import entrance_block

        entrance_block(Shape(sq), Shape(sq + 0.5)).to_shapely()
    elif family == "many moving bodies":
        from .impacts import first_impacts, time_of_impact_many
        from .motion import Motion

        for method in ("exact", "sampled"):
            first_impacts([Shape(sq), Shape(sq + (3.0, 0.0))], [Motion(velocity=(1.0, 0.0)),
                          Motion()], t_max=5.0, method=method, threads=1)
        time_of_impact_many(sq[None], np.array([[1.0, 0, 0, 0, 0, 0]]), sq[None] + 3.0,
                            np.zeros((1, 6)), t_max=5.0, threads=1)  # the packed form
    else:
        raise ValueError(f"family: expected one of {', '.join(FAMILIES)}, got {family!r}")


def warmup(
    families: Iterable[str] = FAMILIES,
    *,
    progress: Callable[[str, int, int, float | None], None] | None = None,
    processes: int = 1,
) -> None:
    """Compile (or load from the cache) the kernels now.

    Numba compiles each kernel on its first call; call this once at start-up to pay
    that cost up front instead of on the first :func:`polycontact.classify`,
    :func:`polycontact.time_of_impact`, :func:`polycontact.no_fit_polygon` or
    :func:`polycontact.entrance_block`.

    Parameters
    ----------
    families : iterable of str, optional
        Which kernel families (keys of :data:`FAMILIES`); all by default.
    progress : callable, optional
        Called as ``progress(family, k, n, seconds)`` before stage ``k`` of ``n``
        (``seconds`` None) and after it (``seconds`` it took). With several processes,
        both calls come when the stage ends, and stages end in any order.
    processes : int, optional
        Compile in this many processes at once (up to one per family; each writes what
        it compiles to the cache, where this process and later ones load it): about
        half the wall time on two idle cores, for somewhat more CPU time (kernels that
        several families run are compiled in each process that needs them). Each
        process numbers the functions it compiles apart from every other process's, so
        that no two give one name to different code in the cache. 1 (the default): in
        this process.

    Examples
    --------
    >>> warmup(["classification"])
    """
    chosen = list(families)
    for family in chosen:
        if family not in FAMILIES:
            raise ValueError(f"families: expected names from {', '.join(FAMILIES)}, got {family!r}")
    if not (isinstance(processes, int) and processes >= 1):
        raise ValueError(f"processes: expected an int >= 1, got {processes!r}")
    if processes > 1 and len(chosen) > 1:
        _warmup_in_processes(chosen, progress, min(processes, len(chosen)))
        return
    for k, family in enumerate(chosen, 1):
        if progress is not None:
            progress(family, k, len(chosen), None)
        t0 = time.perf_counter()
        _run(family)
        if progress is not None:
            progress(family, k, len(chosen), time.perf_counter() - t0)


def _warmup_in_processes(
    chosen: list[str],
    progress: Callable[[str, int, int, float | None], None] | None,
    processes: int,
) -> None:
    """:func:`warmup` of ``chosen`` in ``processes`` worker processes, each family in
    one of them, the longest to compile first (:data:`_COMPILE_SECONDS`)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(processes, mp_context=context, initializer=_worker_start) as pool:
        numbered = sorted(enumerate(chosen, 1), key=lambda kf: -_COMPILE_SECONDS[kf[1]])
        stages = {pool.submit(_timed_run, family): (k, family) for k, family in numbered}
        for done in as_completed(stages):
            k, family = stages[done]
            seconds = done.result()
            if progress is not None:
                progress(family, k, len(chosen), None)
                progress(family, k, len(chosen), seconds)


def _worker_start() -> None:
    """A worker of :func:`warmup`: no compile notice (the caller reports), and the
    functions it compiles numbered from its process id times 2**20 on.

    Numba names compiled code after the function's name, argument types and a number
    that counts up from 1 in each process; two processes can give one name to two
    different functions (helpers that Numba generates share names), and a process that
    later loads code of both from the cache can link the wrong one
    (`numba/numba#10486 <https://github.com/numba/numba/issues/10486>`_). The workers'
    numbers are apart from each other's and from those of every ordinary process.
    """
    import os

    from numba.core.bytecode import FunctionIdentity

    logging.getLogger("polycontact").setLevel(logging.ERROR)
    FunctionIdentity._unique_ids = itertools.count(os.getpid() << 20)


def _timed_run(family: str) -> float:
    t0 = time.perf_counter()
    _run(family)
    return time.perf_counter() - t0
