"""Kernels: how a parallel pass shares its items among its chunks.

The parallel passes run ``for c in prange(chunks)``, and Numba's default threading layer
(OpenMP) hands each thread a fixed, contiguous run of those chunks. Items in a World's
order are often clustered by cost (the bodies of a dense pile and the pairs among them
come together), so a pass whose chunk ``c`` took the c-th contiguous run of items would
leave the threads that drew the cheap runs idle. Instead the items are cut into
:data:`SPREAD` ``* chunks`` consecutive blocks, and chunk ``c`` takes the blocks ``c``,
``c + chunks``, ``c + 2 chunks``, ...: each thread gets a share of every region, in
blocks long enough to keep the locality of consecutive items.
"""

from __future__ import annotations

from .jit import njit

#: Blocks per chunk.
SPREAD = 8


@njit(cache=True, nogil=True, inline="always")
def block(n, chunks, b):
    """Items ``k0:k1`` of block ``b`` of the :data:`SPREAD` ``* chunks`` consecutive
    blocks of ``n`` items; chunk ``c`` takes the blocks ``range(c, SPREAD * chunks,
    chunks)``.

    >>> block(100, 2, 3)
    (18, 25)
    """
    blocks = SPREAD * chunks
    return n * b // blocks, n * (b + 1) // blocks
