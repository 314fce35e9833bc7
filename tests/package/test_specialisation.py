"""One compile per kernel: a kernel made by ``polycontact._kernels.jit.njit`` compiles
once for callers that pass read-only or writable arrays, constants or variables, keeps
the types of what it writes or returns, and falls back to the exact types when its
relaxed form does not compile. (Compiled code: skipped with ``NUMBA_DISABLE_JIT=1``.)"""

from __future__ import annotations

import threading

import numpy as np
import pytest
from numba import config, types

from polycontact._kernels import jit
from polycontact._kernels.jit import njit, relaxed_types

pytestmark = pytest.mark.skipif(config.DISABLE_JIT, reason="compiled code only")


def _readonly(a: np.ndarray) -> np.ndarray:
    v = a.view()
    v.flags.writeable = False
    return v


@njit
def _copy_first(x, out):
    out[0] = x[0]


@njit
def _scaled(x, k):
    return x[0] * k


@njit
def _calls_scaled_with_a_constant_and_a_variable(x, k):
    return _scaled(x, 2) + _scaled(x, k) + _scaled(x[1:], 3)


@njit
def _tail(x):
    return x[1:]


@njit
def _zero_tail(x):
    t = _tail(x)
    t[0] = 0.0
    return x[0]


@njit
def _sum_first_two(x):
    return x[0] + x[1]


def test_read_only_and_writable_arrays_share_one_compile():
    x, out = np.arange(3.0), np.zeros(1)
    _copy_first(_readonly(x + 1.0), out)
    assert out[0] == 1.0
    _copy_first(x, out)
    assert out[0] == 0.0
    assert len(_copy_first.overloads) == 1
    (args,) = _copy_first.overloads
    assert not args[0].mutable and args[1].mutable  # read from: read-only; written: kept


def test_constants_and_variables_share_one_compile():
    x = np.array([2.0, 5.0])
    assert _calls_scaled_with_a_constant_and_a_variable(x, 4) == 4.0 + 8.0 + 15.0
    assert _calls_scaled_with_a_constant_and_a_variable(_readonly(x), 4) == 27.0
    assert len(_scaled.overloads) == 1
    assert len(_calls_scaled_with_a_constant_and_a_variable.overloads) == 1


def test_a_view_returned_keeps_its_type_so_callers_may_write_it():
    x = np.array([1.0, 2.0, 3.0])
    assert _zero_tail(x) == 1.0 and x.tolist() == [1.0, 0.0, 3.0]
    (args,) = _tail.overloads
    assert args[0].mutable
    # a number read from an array is not a view of it
    assert relaxed_types(_scaled, (types.float64[::1], types.literal(2))) == (
        types.float64[::1].copy(readonly=True), types.int64)


def test_a_read_only_array_given_to_be_written_is_refused_as_numba_does():
    with pytest.raises(Exception, match="readonly|read-only"):
        _copy_first(np.arange(3.0), _readonly(np.zeros(1)))


def test_a_write_the_reading_misses_compiles_for_the_exact_types(monkeypatch):
    @njit
    def fill(out):
        out[0] = 7.0

    reading = jit._Reading()
    reading.uses = reading.returned = frozenset()  # claims that nothing is written
    monkeypatch.setitem(jit._READINGS, fill.py_func, reading)
    out = np.zeros(2)
    fill(out)
    assert out.tolist() == [7.0, 0.0]
    (args,) = fill.overloads
    assert args[0].mutable


def test_a_kernel_first_called_by_two_threads_at_once_is_then_called_directly(monkeypatch):
    # threads that first call a kernel at the same time each ask for its compile (with
    # writable arrays: the specialisation takes them read-only); every later call must
    # still go straight to the compiled code, not through the dispatcher's Python path
    x = np.arange(3.0)
    start = threading.Barrier(2)

    def first_call() -> None:
        start.wait()
        _sum_first_two(x)

    threads = [threading.Thread(target=first_call) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    slow: list[object] = []
    real = _sum_first_two._compile_for_args

    def counted(*args: object, **kws: object) -> object:
        slow.append(args)
        return real(*args, **kws)

    monkeypatch.setattr(_sum_first_two, "_compile_for_args", counted)
    assert [_sum_first_two(x) for _ in range(3)] == [1.0, 1.0, 1.0]
    assert slow == []


def test_the_pairwise_kernels_compile_once_for_shapes_and_batches():
    # time_of_impact passes a Shape's read-only arrays, first_impacts a batch's own
    # writable ones; both reach the same search and depth kernels, compiled (or loaded
    # from the cache, where a kernel's callers hold its code) for one set of types
    import polycontact as pc
    from polycontact._kernels import convolution, impact

    sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    far = sq.moved((3.0, 0.0))
    hit = pc.time_of_impact(sq, pc.Motion(velocity=(1.0, 0.0)), far, pc.Motion(), t_max=5.0)
    hit.features  # noqa: B018 - computed on access
    pc.first_impacts([sq, far], [pc.Motion(velocity=(1.0, 0.0)), pc.Motion()], t_max=5.0,
                     threads=1)
    for kernel in (impact.exact_query, impact.state_at, convolution.contact_depth):
        cache = kernel._cache
        probe = cache._index_key((), kernel.targetctx.codegen())
        cached = [key[0] for key in cache._cache_file._load_index() if key[1:] == probe[1:]]
        assert len(set(cached) | set(kernel.overloads)) == 1, (kernel, cached)
