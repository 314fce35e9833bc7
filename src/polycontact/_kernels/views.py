"""Kernels' memory: views of a flat buffer as arrays of another shape or type, and
scratch on the stack, with no allocation and no call into Numba's helpers.

A Numba ``reshape`` calls a helper of Numba's C library and ``view`` checks its
arguments at run time: the dozen views that the state kernel of two 12-gons takes of
the shapes' kernel packs and of its scratch cost about 0.1 µs of its 0.4-0.6 µs
(measured warm, one process). Here a view is a pointer and a shape written straight
into the array's structure. With ``NUMBA_DISABLE_JIT=1`` the same functions are plain
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
from numba import types
from numba.core import cgutils, config
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


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
