"""Kernels' memory: views of a flat buffer as arrays of another shape or type, scratch on
the stack, the state kernel's scratch, and a shape's kernel pack, with no allocation and
no call into Numba's helpers.

A Numba ``reshape`` calls a helper of Numba's C library and ``view`` checks its
arguments at run time: for the dozen views that the state kernel of two small shapes
takes of the shapes' kernel packs and of its scratch, that is a sizeable part of the
kernel's time. Here a view is a pointer and a shape written straight into the array's
structure. With ``NUMBA_DISABLE_JIT=1`` the same functions are plain
NumPy slicing, so the kernels' bodies run (and are tested) as Python.

The caller guarantees the bounds: ``view(buf, start, n, k, dtype)`` must lie inside
``buf`` (nothing is checked in compiled code).

Compiled code gets Numba intrinsics (callable only from compiled code); with the JIT
disabled, the NumPy functions ``_view_py``, ``_vector_py`` and ``_stack_floats_py``,
which say what each returns.

Examples
--------
>>> import numpy as np
>>> from numba import njit
>>> @njit
... def rows_and_bits(buf):
...     return view(buf, 2, 3, 2, np.float64)[2, 1], vector(buf, 9, 1, np.int64)[0]
>>> rows_and_bits(np.r_[np.arange(9.0), 2.0**-1074])  # row 2 of the view; a float's bits
(7.0, 1)
"""

from __future__ import annotations

import numpy as np
from numba import prange, types
from numba.core import cgutils, config
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

from .jit import njit


def _dtype_of(dtype):
    """The Numba scalar type of a dtype argument (``np.int64`` and the like), or None."""
    if isinstance(dtype, (types.NumberClass, types.DType)):
        return dtype.dtype
    return None


def _flat_c(buf):
    """A flat C-contiguous array or buffer (``bytes`` too: a kernel pack is one)."""
    return isinstance(buf, types.Buffer) and buf.ndim == 1 and buf.layout == "C"


def _lower_view(ndim):
    """Code of a C-contiguous view of ``ndim`` dimensions of ``buf[start:]``: the data
    pointer moved by ``start`` elements of ``buf`` and cast, the shape from the
    arguments, the strides from the shape; ``buf``'s owner (meminfo and parent) kept,
    with a reference taken where reference counting is on."""

    def codegen(context, builder, sig, args):
        src = make_array(sig.args[0])(context, builder, args[0])
        out = make_array(sig.return_type)(context, builder)
        itemsize = context.get_constant(
            types.intp, context.get_abi_sizeof(context.get_data_type(sig.return_type.dtype)))
        start = context.cast(builder, args[1], sig.args[1], types.intp)
        data = builder.bitcast(builder.gep(src.data, [start]), out.data.type)
        shape = [context.cast(builder, args[i], sig.args[i], types.intp)
                 for i in range(2, 2 + ndim)]
        strides = [itemsize] if ndim == 1 else [builder.mul(shape[1], itemsize), itemsize]
        populate_array(out, data=data, shape=shape, strides=strides, itemsize=itemsize,
                       meminfo=src.meminfo, parent=src.parent)
        return impl_ret_borrowed(context, builder, sig.return_type, out._getvalue())

    return codegen


@intrinsic
def _view(typingctx, buf, start, n, k, dtype):
    dt = _dtype_of(dtype)
    if dt is None or not _flat_c(buf):
        return None
    out = types.Array(dt, 2, "C", readonly=not buf.mutable)
    return out(buf, start, n, k, dtype), _lower_view(2)


@intrinsic
def _vector(typingctx, buf, start, n, dtype):
    dt = _dtype_of(dtype)
    if dt is None or not _flat_c(buf):
        return None
    out = types.Array(dt, 1, "C", readonly=not buf.mutable)
    return out(buf, start, n, dtype), _lower_view(1)


@intrinsic
def _stack_floats(typingctx, size):
    if not isinstance(size, types.IntegerLiteral):
        return None
    out = types.Array(types.float64, 1, "C")

    def codegen(context, builder, sig, args):
        count = context.get_constant(types.intp, size.literal_value)
        data = cgutils.alloca_once(builder, context.get_data_type(types.float64), size=count)
        arr = make_array(out)(context, builder)
        itemsize = context.get_constant(types.intp, 8)
        populate_array(arr, data=data, shape=[count], strides=[itemsize], itemsize=itemsize,
                       meminfo=None, parent=None)
        return arr._getvalue()

    return out(size), codegen


def _flat_py(buf):
    """``buf`` as a NumPy array (``bytes`` as read-only uint8)."""
    return buf if isinstance(buf, np.ndarray) else np.frombuffer(buf, dtype=np.uint8)


def _view_py(buf, start, n, k, dtype):
    """``buf[start:]`` (a flat C-contiguous array, or ``bytes``) read as a C-contiguous
    (n, k) array of ``dtype``, writable if ``buf`` is; ``start`` counts elements of
    ``buf``."""
    return _flat_py(buf)[start:].view(dtype)[: n * k].reshape(n, k)


def _vector_py(buf, start, n, dtype):
    """``buf[start:]`` read as a vector of n elements of ``dtype``."""
    return _flat_py(buf)[start:].view(dtype)[:n]


def _stack_floats_py(size):
    """A float64 vector of ``size`` (a literal) elements, uninitialised; compiled, it is
    on the stack of the function that calls it, valid until that function returns (so
    that function must return no view of it)."""
    return np.empty(size)


if config.DISABLE_JIT:  # the kernels run as Python: the same views by NumPy slicing
    view, vector, stack_floats = _view_py, _vector_py, _stack_floats_py
else:
    view, vector, stack_floats = _view, _vector, _stack_floats


@njit(cache=True, nogil=True)
def scratch_floats(size):
    """Length of a float64 buffer that holds the scratch of the state kernel for pairs
    of up to ``size`` vertices in all (see
    :func:`polycontact._kernels.relation.relate_shapes_into`).

    >>> scratch_floats(24)
    554
    """
    r = size + 1
    return 22 * r + (size + 8) // 8


@njit(cache=True, nogil=True)
def state_scratch(size):
    """Scratch buffers for :func:`polycontact._kernels.relation.state_in` for up to
    ``size`` vertices in all: edge boxes, edge ids, touch flags, and the rays at one
    touch point with their order (views of one allocation)."""
    return state_scratch_views(np.empty(scratch_floats(size)), size)


@njit(cache=True, nogil=True, inline="always")
def state_scratch_views(buf, size):
    """:func:`state_scratch`'s five buffers as views of ``buf`` (of at least
    ``scratch_floats(size)`` floats): edge boxes (r, 4), edge ids (r, 4) int64, touch
    flags, rays (2 r, 6), ray order (2 r) int64, with r = size + 1."""
    r = size + 1
    return (
        view(buf, 0, r, 4, np.float64),
        view(buf, 16 * r, r, 4, np.int64),
        vector(buf, 22 * r, 8 * (scratch_floats(size) - 22 * r), np.bool_),
        view(buf, 4 * r, 2 * r, 6, np.float64),
        vector(buf, 20 * r, 2 * r, np.int64),
    )


#: Layout of a shape's kernel pack (``Shape._kernel``, built once per shape by
#: :func:`polycontact.shape._kernel_pack`): one ``bytes`` object holding, as float64,
#: the loop count, the bounding box as ``(xmin, ymin, xmax, ymax)``, the shape's
#: default-tolerance term (``Shape._tolerance``: the kernel takes the larger of the two
#: shapes', so the caller reads no float object), the loop starts (int64 bit patterns,
#: L + 1 of them), the packed coordinates row by row, and last the :data:`PACK_TAIL`
#: sizes (what a batch of moving bodies reads of each shape). A
#: ``bytes`` object holds its data in itself: unboxing it reads one object, where an
#: ndarray's header, shape and data are three (which counts when other code has evicted
#: the caches).
PACK_HEAD = 6

#: The floats after a kernel pack's coordinates: the shape's area centroid ``(x, y)``,
#: its bounding radius about it and its extent (the larger side of its box).
PACK_TAIL = 4


@njit(cache=True, nogil=True, inline="always")
def unpack_shape(pack):
    """``(xy, starts, box, tolerance)`` of a shape's kernel pack (views: nothing is
    allocated), the box as ``(xmin, xmax, ymin, ymax)``, the shape's default-tolerance
    term."""
    pack = vector(pack, 0, len(pack) // 8, np.float64)
    nl = int(pack[0])
    starts = vector(pack, PACK_HEAD, nl + 1, np.int64)
    n = starts[nl]
    xy = view(pack, PACK_HEAD + nl + 1, n, 2, np.float64)
    return xy, starts, (pack[1], pack[3], pack[2], pack[4]), pack[5]


#: Vertices (both bodies together) of the pairs
#: :func:`polycontact._kernels.relation.relate_shapes_into` classifies with its scratch
#: on the stack (45 kB); larger pairs take
#: :func:`polycontact._kernels.relation.relate_state`, whose allocation costs little
#: beside their test.
STACK_VERTICES = 256

#: Floats of that stack scratch: :func:`scratch_floats` of :data:`STACK_VERTICES`.
STACK_FLOATS = getattr(scratch_floats, "py_func", scratch_floats)(STACK_VERTICES)


@njit(cache=True, nogil=True)
def _unpack_into(blob, bits, at, rows, st_off, k0, k1, xy, starts, sizes):
    """Shapes ``k0..k1`` of :func:`unpack_shapes` (their packs at ``blob[at[k]:]``)
    copied into ``xy``, ``starts`` and ``sizes``."""
    for k in range(k0, k1):
        o = at[k]
        m = st_off[k + 1] - st_off[k]
        starts[st_off[k] : st_off[k + 1]] = bits[o + PACK_HEAD : o + PACK_HEAD + m]
        first = o + PACK_HEAD + m
        n = rows[k + 1] - rows[k]
        for i in range(n):
            xy[rows[k] + i, 0] = blob[first + 2 * i]
            xy[rows[k] + i, 1] = blob[first + 2 * i + 1]
        for i in range(PACK_TAIL):
            sizes[k, i] = blob[first + 2 * n + i]


@njit(cache=True, nogil=True, parallel=True)
def unpack_shapes(blob, count, chunks):
    """The shapes of ``count`` kernel packs (the layout of :data:`PACK_HEAD`) one after
    another in ``blob`` (float64), as ``(xy, rows, starts, st_off, sizes)``: shape k's
    rows ``xy[rows[k]:rows[k + 1]]``, its loop starts (from 0)
    ``starts[st_off[k]:st_off[k + 1]]`` and its :data:`PACK_TAIL` sizes ``sizes[k]``;
    copied in ``chunks`` parallel chunks (1: serial, no thread start)."""
    bits = blob.view(np.int64)
    rows = np.zeros(count + 1, np.int64)
    st_off = np.zeros(count + 1, np.int64)
    at = np.empty(count, np.int64)
    o = 0
    for k in range(count):
        nl = int(blob[o])
        n = bits[o + PACK_HEAD + nl]
        at[k] = o
        rows[k + 1] = rows[k] + n
        st_off[k + 1] = st_off[k] + nl + 1
        o += PACK_HEAD + nl + 1 + 2 * n + PACK_TAIL
    xy = np.empty((rows[count], 2))
    starts = np.empty(st_off[count], np.int64)
    sizes = np.empty((count, PACK_TAIL))
    if chunks == 1:
        _unpack_into(blob, bits, at, rows, st_off, 0, count, xy, starts, sizes)
        return xy, rows, starts, st_off, sizes
    for c in prange(chunks):
        _unpack_into(blob, bits, at, rows, st_off, count * c // chunks,
                     count * (c + 1) // chunks, xy, starts, sizes)
    return xy, rows, starts, st_off, sizes
