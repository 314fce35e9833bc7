"""Calling a compiled kernel without the Numba dispatcher's per-call type resolution.

A Numba dispatcher finds the machine code for each call from the types of its arguments.
For writable arrays it has a fast path; for read-only ones (every array a
:class:`~polycontact.Shape` holds is read-only, so that it cannot go stale) and for
tuples it falls back to a Python-level ``typeof`` per argument, which costs about a
microsecond per call, more than the classification of two 12-gons. The public functions
whose kernel arguments have types fixed by construction (a Shape's arrays, a Motion's
vector, floats they made themselves) call the compiled entry point directly instead.

Examples
--------
>>> import numpy as np
>>> from numba import njit
>>> @njit
... def total(x, k):
...     return x.sum() * k
>>> fast = entry_point(total, (np.ones(3), 2.0))
>>> fast(np.ones(3), 2.0)
6.0
"""

from __future__ import annotations

from typing import Any, Callable


def entry_point(dispatcher: Any, args: tuple[Any, ...]) -> Callable[..., Any]:
    """The compiled code of ``dispatcher`` for the types of ``args``, as a callable.

    Compiles (or loads from the cache) that specialisation by one call with ``args`` if
    it does not exist yet, so ``args`` must be a valid call without side effects. The
    callable does not check its arguments: call it only with arguments of exactly the
    types of ``args`` (same dtypes, dimensions, layout and writability). Falls back to
    the dispatcher itself when Numba does not expose the compiled code.
    """
    try:
        from numba import typeof

        from ._kernels.jit import accepts

        key = tuple(typeof(x) for x in args)  # type: ignore[no-untyped-call]
        found = dispatcher.overloads.get(key)
        if found is None:
            dispatcher(*args)
            # (a kernel compiles for the relaxed types of its arguments: see _kernels.jit)
            found = next((cres for have, cres in dispatcher.overloads.items()
                          if accepts(have, key)), None)
        fast = getattr(found, "entry_point", None)
    except Exception:  # noqa: BLE001 - any change in Numba's internals: the safe way
        fast = None
    chosen: Callable[..., Any] = dispatcher if fast is None else fast
    return chosen
