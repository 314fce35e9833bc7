"""The kernels' decorator: :func:`njit`, Numba's ``njit`` compiling one specialisation of
a kernel where Numba would compile several.

Numba compiles a function once per distinct tuple of argument types, with everything it
calls. A kernel reached with a read-only array (every array a Shape holds) and with a
writable one (a batch's arrays, a kernel's own buffers), or with a constant
(``Literal[int](0)``) and with a variable, is compiled twice, and so is every kernel it
calls. A kernel made by :func:`njit` compiles for the *relaxed* types of its arguments
instead: an array it neither writes nor returns (nor passes on to be written) is typed
read-only, a constant is typed as its plain type. A call with stricter types converts
to those (Numba converts a writable array to a read-only one, and a constant to its
type, at no cost), so one specialisation serves every caller: from Python, from other
kernels, and from the disk cache in a later run. The machine code does not depend on
these types, so neither do the answers.

What a kernel writes is read from its Numba IR when it is first compiled (never when
it is loaded from the cache); the reading is conservative (whatever may be written or
returned keeps the caller's type). A kernel whose relaxed form does not compile all the
same (a write the reading missed) is compiled for the exact types, as Numba would.

With ``NUMBA_DISABLE_JIT=1`` :func:`njit` returns the function unchanged, as Numba's does.

Examples
--------
>>> from numba import types
>>> @njit
... def first(x, out):
...     out[0] = x[0]
...     return out
>>> vector = types.float64[::1]
>>> [str(t) for t in relaxed_types(first, (vector, vector))]  # x read-only; out kept
['readonly array(float64, 1d, C)', 'array(float64, 1d, C)']
"""

from __future__ import annotations

import inspect
import logging
import math
import operator
import threading
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
from numba import config, literal_unroll, prange, types
from numba.core import errors, event, ir, sigutils
from numba.core.compiler import run_frontend
from numba.core.compiler_lock import global_compiler_lock
from numba.core.registry import CPUDispatcher

from .cache import cache_directory

__all__ = ["COMPILE_NOTICE", "LOGGER", "Kernel", "install_compile_notice", "njit",
           "relaxed_types"]

#: polycontact's logger: the compile notice is a warning on it (shown on stderr when
#: logging is not configured); ``LOGGER.setLevel(logging.ERROR)`` silences it.
LOGGER = logging.getLogger("polycontact")

#: What the first compile of a process says (``{where}``: the cache's directory).
COMPILE_NOTICE = ("polycontact is compiling the kernels this call needs, once: {estimate} "
                  "(then cached in {where}; `polycontact warmup` compiles them all ahead)")

#: The compile time of a first call, as the notice states it (a classification
#: compiles the fewest kernels, a no-fit polygon the most).
COMPILE_ESTIMATE = "10 s to a minute, depending on the call"

#: A path into an argument: tuple indices from the argument down to an array.
Path = tuple[int, ...]

#: Callables that neither write their arguments nor return a view of them.
_PURE: frozenset[Any] = frozenset({
    len, range, min, max, abs, int, float, bool, round, divmod, pow, slice, print,
    isinstance, hash,
    np.empty, np.zeros, np.ones, np.full, np.empty_like, np.zeros_like, np.ones_like,
    np.full_like, np.arange, np.linspace, np.copy, np.array, np.concatenate, np.stack,
    np.vstack, np.hstack, np.sort, np.argsort, np.cumsum, np.searchsorted, np.unique,
    np.dot, np.argmin, np.argmax, np.nonzero, np.where, np.isfinite, np.isnan, np.isinf,
    np.any, np.all, np.sum, np.prod, np.min, np.max, np.amin, np.amax, np.mean,
    np.median, np.floor, np.ceil, np.sign, np.nextafter, np.spacing, np.finfo,
    np.iinfo, np.int64, np.float64, np.int32, np.uint64, np.bool_, np.uint8, np.intp,
    prange,
}) | frozenset(v for v in vars(math).values() if callable(v))

#: Callables that return a view of (or an iterator over) their arguments without
#: writing them.
_VIEWS: frozenset[Any] = frozenset({
    np.asarray, np.ascontiguousarray, np.asfortranarray, np.atleast_1d, np.atleast_2d,
    np.reshape, np.ravel, np.transpose, np.expand_dims, np.squeeze, np.swapaxes,
    np.diagonal, np.real, np.imag, np.flip, np.broadcast_to, enumerate, zip, reversed,
    iter, next, literal_unroll,
})

#: Methods of an array that neither write it nor return a view of it.
_PURE_METHODS = frozenset({
    "copy", "sum", "prod", "min", "max", "argmin", "argmax", "mean", "std", "var", "any",
    "all", "astype", "argsort", "cumsum", "cumprod", "dot", "item", "nonzero", "tolist",
    "flatten", "searchsorted", "conj", "shape", "size", "ndim", "dtype", "itemsize",
    "nbytes", "strides",
})

#: Methods and attributes that return a view of the array (they do not write it).
_VIEW_METHODS = frozenset({"reshape", "ravel", "view", "transpose", "T", "squeeze",
                           "swapaxes", "diagonal", "real", "imag", "flat"})


def njit(function: Callable[..., Any] | None = None, **options: Any) -> Any:
    """Numba's ``njit`` (same options), the kernel compiled for its relaxed argument
    types (see the module's description); the function itself when the JIT is off."""
    if function is None:
        return lambda f: njit(f, **options)
    if config.DISABLE_JIT:
        return function
    cache = options.pop("cache", False)
    options["nopython"] = True
    options.setdefault("boundscheck", None)
    kernel = Kernel(py_func=function, locals={}, targetoptions=options)
    if cache:
        kernel.enable_caching()
    return kernel


class Kernel(CPUDispatcher):  # type: ignore[misc]
    """A Numba dispatcher that compiles one specialisation for calls whose argument
    types differ only in read-only arrays and constants (see the module)."""

    def compile(self, sig: Any) -> Any:
        args, return_type = sigutils.normalize_signature(sig)
        args = tuple(args)
        if return_type is not None or args in self.overloads or not self._can_compile:
            return super().compile(sig)
        with global_compiler_lock:
            chosen = self._compiled_relative(args)
            guessed = chosen is None
            if guessed:
                chosen = relaxed_types(self, args)
            if chosen == args:
                return super().compile(args)
            try:
                entry = super().compile(chosen)
            except errors.NumbaError:
                if not guessed:
                    raise
                return super().compile(args)  # a write the reading missed: exact types
            # Python calls with these types go straight to it from now on: once (threads
            # that first call at once all come here; a second entry for the same types
            # would make Numba's lookup ambiguous, and every later call slow)
            codes = tuple(a._code for a in args)
            direct = self.__dict__.setdefault("_direct", set())
            if codes not in direct:
                direct.add(codes)
                self._insert(list(codes), entry, False)
            return entry

    def _compiled_relative(self, args: tuple[Any, ...]) -> tuple[Any, ...] | None:
        """Argument types of a specialisation in memory, or in the disk cache, that
        ``args`` convert to for free; None if there is none."""
        for have in self.overloads:
            if accepts(have, args):
                return tuple(have)
        try:  # the cache's index (Numba's internals: any doubt means "none")
            cache = self._cache
            index = cache._cache_file._load_index()
            probe = cache._index_key(args, self.targetctx.codegen())
        except Exception:  # noqa: BLE001
            return None
        for key in index:
            have = key[0]
            if key[1:] == probe[1:] and isinstance(have, tuple) and accepts(have, args):
                return have
        return None


class _CompileNotice(event.Listener):  # type: ignore[misc]
    """Says :data:`COMPILE_NOTICE` when a kernel first starts compiling (not when it is
    loaded from the cache), once per process."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._said = False

    def on_start(self, ev: Any) -> None:
        if self._said or not isinstance(ev.data.get("dispatcher"), Kernel):
            return
        with self._lock:
            if self._said:
                return
            self._said = True
        LOGGER.warning(COMPILE_NOTICE.format(estimate=COMPILE_ESTIMATE, where=cache_directory()))

    def on_end(self, ev: Any) -> None:
        pass


_NOTICES: list[_CompileNotice] = []


def install_compile_notice() -> None:
    """Make the first kernel compile of the process say so (:class:`_CompileNotice`);
    called by ``polycontact._kernels`` before any kernel is defined."""
    if not _NOTICES:
        _NOTICES.append(_CompileNotice())
        event.register("numba:compile", _NOTICES[0])


def accepts(have: Iterable[Any], args: Iterable[Any]) -> bool:
    """Whether a specialisation for argument types ``have`` takes arguments of types
    ``args`` with no conversion but read-only arrays and plain types of constants."""
    have, args = tuple(have), tuple(args)
    return len(have) == len(args) and all(_fits(a, h) for a, h in zip(args, have))


def _fits(actual: Any, formal: Any) -> bool:
    if actual == formal:
        return True
    if isinstance(actual, types.Literal):
        return _fits(types.unliteral(actual), formal)
    if type(actual) is types.Array and type(formal) is types.Array:
        return (not formal.mutable and actual.dtype == formal.dtype
                and actual.ndim == formal.ndim and actual.layout == formal.layout
                and actual.aligned == formal.aligned)
    if _plain_tuple(actual) and _plain_tuple(formal):
        return len(actual) == len(formal) and all(_fits(a, f) for a, f in zip(actual, formal))
    return False


def _plain_tuple(t: Any) -> bool:
    return isinstance(t, (types.Tuple, types.UniTuple))


def relaxed_types(kernel: Any, args: Iterable[Any]) -> tuple[Any, ...]:
    """The argument types ``kernel`` compiles for when called with types ``args``:
    constants as their plain types, and arrays read-only where the kernel neither
    writes them, nor returns a view of them, nor passes them on to be written."""
    args = tuple(args)
    uses = _reading(getattr(kernel, "py_func", kernel)).uses
    kept: set[tuple[int, Path]] | None = None
    if uses is not None:
        kept = set()
        for k, chain in uses:
            if 0 <= k < len(args):
                found = _locate(args[k], chain)
                if found is not None:
                    kept.add((k, found))
    return tuple(_relax(t, (k, ()), kept) for k, t in enumerate(args))


def _relax(t: Any, where: tuple[int, Path], kept: set[tuple[int, Path]] | None) -> Any:
    if isinstance(t, types.Literal):
        t = types.unliteral(t)
    if type(t) is types.Array:
        return t if not t.mutable or _touched(where, kept) else t.copy(readonly=True)
    if _plain_tuple(t):
        k, path = where
        return types.Tuple([_relax(e, (k, (*path, i)), kept) for i, e in enumerate(t)])
    return t


def _touched(where: tuple[int, Path], kept: set[tuple[int, Path]] | None) -> bool:
    """Whether the part ``where`` of an argument, or a part of it or around it, is kept
    (None: everything is)."""
    if kept is None:
        return True
    k, path = where
    return any(j == k and (p[: len(path)] == path or path[: len(p)] == p) for j, p in kept)


#: A step from a value to a part of it: ``int`` j, item j (of a tuple; of an array,
#: an index); ``("n", c)``, an item of a tuple not known, or an array indexed by c
#: numbers (and any slices).
Step = Any
Chain = tuple[Step, ...]


def _locate(t: Any, chain: Chain) -> Path | None:
    """The path to the array, or tuple, of argument type ``t`` that ``chain`` reaches a
    view of; None when it reaches a number (an array indexed in all its dimensions) or
    anything else that is not a view."""
    path: Path = ()
    used = 0  # array dimensions indexed so far
    for step in chain:
        if _plain_tuple(t):
            if not isinstance(step, int) or not 0 <= step < len(t):
                return path  # some item: the whole tuple
            t, path = t[step], (*path, step)
        elif isinstance(t, types.Buffer):
            used += 1 if isinstance(step, int) else step[1]
        else:
            return None
    if isinstance(t, types.Buffer):
        return path if used < t.ndim else None
    return path if _plain_tuple(t) else None


class _Reading:
    """What a function may do to its arguments, read from its Numba IR: ``uses``, the
    parts ``(argument, chain)`` it may write, return, or pass on to be written (None:
    any part of any argument); ``returned``, the parts its result may hold (None: any).
    A part counts only where it is a view (:func:`_locate`): a number read from an
    array and returned is not its array."""

    uses: frozenset[tuple[int, Chain]] | None
    returned: frozenset[tuple[int, Chain]] | None

    def __init__(self) -> None:
        self.uses = self.returned = None  # (while being read: a recursive call keeps all)

    def read(self, func: Callable[..., Any]) -> None:
        """Read ``func``; on any construct this reading does not know, keep all."""
        try:
            self._read(func)
        except Exception:  # noqa: BLE001
            self.uses = self.returned = None

    def _read(self, func: Callable[..., Any]) -> None:
        fir = run_frontend(func)
        self._defs: dict[str, list[Any]] = {}
        stmts = [s for block in fir.blocks.values() for s in block.body]
        for s in stmts:
            if isinstance(s, ir.Assign):
                self._defs.setdefault(s.target.name, []).append(s.value)
        self._all = False
        uses: set[tuple[int, Chain]] = set()
        returned: set[tuple[int, Chain]] = set()
        for s in stmts:
            if isinstance(s, (ir.SetItem, ir.StaticSetItem, ir.SetAttr)):
                uses |= self._parts(s.target)
            elif isinstance(s, ir.Return):
                returned |= self._parts(s.value)
            elif isinstance(s, ir.Assign) and isinstance(s.value, ir.Expr):
                uses |= self._writes(s.value)
        if not self._all:
            self.returned = frozenset(returned)
            self.uses = frozenset(uses | returned)

    # -- what a variable may be a part of ----------------------------------------------
    def _parts(self, var: ir.Var, then: Chain = (), seen: frozenset[Any] = frozenset()
               ) -> set[tuple[int, Chain]]:
        """The argument parts ``(argument, chain)`` that variable ``var``, followed by
        the steps ``then``, may be."""
        key = (var.name, then)
        if key in seen:
            return set()
        seen = seen | {key}
        out: set[tuple[int, Chain]] = set()
        for value in self._defs.get(var.name, ()):
            out |= self._value_parts(value, then, seen)
        return out

    def _value_parts(self, value: Any, then: Chain, seen: frozenset[Any]
                     ) -> set[tuple[int, Chain]]:
        if isinstance(value, ir.Arg):
            return {(value.index, then)}
        if isinstance(value, ir.Var):
            return self._parts(value, then, seen)
        if not isinstance(value, ir.Expr):
            return set()  # constants, globals
        op = value.op
        if op == "build_tuple":
            items = value.items
            if then and isinstance(then[0], int) and 0 <= then[0] < len(items):
                items = [items[then[0]]]
            rest = then[1:] if then else ()
            return set().union(*(self._parts(v, rest, seen) for v in items))
        if op in ("getitem", "static_getitem", "typed_getitem"):
            step = self._step(value)
            return self._parts(value.value, then if step is None else (step, *then), seen)
        if op == "getiter":
            return self._parts(value.value, (("n", 1), *then), seen)
        if op in ("exhaust_iter", "iternext", "pair_first", "cast"):
            return self._parts(value.value, then, seen)
        if op == "getattr":
            if value.attr in _PURE_METHODS:
                return set()
            return self._parts(value.value, then, seen)
        if op in ("binop", "unary", "pair_second", "phi", "null", "undef"):
            if op == "binop" and value.fn is operator.add:  # tuples joined: any part
                return self._parts(value.lhs, (), seen) | self._parts(value.rhs, (), seen)
            return set()
        if op == "call":
            return self._call_result(value, seen)
        return set().union(*(self._parts(v, (), seen) for v in value.list_vars()))

    def _step(self, expr: ir.Expr) -> Step | None:
        """The step of an indexing expression (None: a slice, the whole)."""
        if expr.op == "static_getitem":
            index = expr.index
        else:
            value = self._single(expr.index)
            if isinstance(value, ir.Const):
                index = value.value
            elif isinstance(value, ir.Expr) and value.op == "build_tuple":
                return ("n", sum(not self._is_slice(v) for v in value.items))
            else:
                return None if self._is_slice(expr.index) else ("n", 1)
        if isinstance(index, slice):
            return None
        if isinstance(index, tuple):
            return ("n", sum(not isinstance(i, slice) for i in index))
        return index if isinstance(index, int) else ("n", 1)

    def _is_slice(self, var: ir.Var) -> bool:
        value = self._single(var)
        if isinstance(value, ir.Const):
            return isinstance(value.value, slice)
        return (isinstance(value, ir.Expr) and value.op == "call"
                and self._resolve(value.func) is slice)

    def _call_result(self, call: ir.Expr, seen: frozenset[Any]) -> set[tuple[int, Chain]]:
        """What the result of ``call`` may be a part of (where in it: anywhere)."""
        method = self._method(call.func)
        if method is not None:
            owner, name = method
            return set() if name in _PURE_METHODS else self._parts(owner, (), seen)
        target = self._resolve(call.func)
        if _among(target, _PURE):
            return set()
        reading = _callee_reading(target)
        bound = _bind(target, call)
        if _among(target, _VIEWS) or reading is None or bound is None or reading.returned is None:
            return set().union(*(self._parts(v, (), seen) for v in _call_vars(call)))
        out: set[tuple[int, Chain]] = set()
        for k, chain in reading.returned:
            if k in bound:
                out |= self._parts(bound[k], chain, seen)
        return out

    # -- what an expression may write ---------------------------------------------------
    def _writes(self, expr: ir.Expr) -> set[tuple[int, Chain]]:
        if expr.op == "inplace_binop":
            return self._parts(expr.lhs)
        if expr.op == "make_function":
            self._all = True  # a closure over the arguments: not followed
            return set()
        if expr.op != "call":
            return set()
        out: set[tuple[int, Chain]] = set()
        for name, var in expr.kws:
            if name == "out":
                out |= self._parts(var)
        method = self._method(expr.func)
        if method is not None:
            owner, name = method
            return out if name in _PURE_METHODS | _VIEW_METHODS else out | self._parts(owner)
        target = self._resolve(expr.func)
        if _among(target, _PURE | _VIEWS):
            return out
        if isinstance(target, np.ufunc):
            for var in expr.args[target.nin:]:
                out |= self._parts(var)
            return out
        reading = _callee_reading(target)
        bound = _bind(target, expr)
        if reading is None or bound is None or reading.uses is None:
            return out | set().union(*(self._parts(v) for v in _call_vars(expr)))
        for k, chain in reading.uses - reading.returned:  # (a result: where it goes)
            if k in bound:
                out |= self._parts(bound[k], chain)
        return out

    # -- names ------------------------------------------------------------------------
    def _single(self, var: ir.Var) -> Any:
        values = self._defs.get(var.name, ())
        return values[0] if len(values) == 1 else None

    def _resolve(self, var: ir.Var) -> Any:
        """The global object ``var`` names (``np.empty``, a kernel), or None."""
        value = self._single(var)
        if isinstance(value, (ir.Global, ir.FreeVar)):
            return value.value
        if isinstance(value, ir.Expr) and value.op == "getattr":
            owner = self._resolve(value.value)
            if inspect.ismodule(owner) or isinstance(owner, type):
                return getattr(owner, value.attr, None)
        return None

    def _method(self, var: ir.Var) -> tuple[ir.Var, str] | None:
        """``(object, name)`` when ``var`` is a method of a local value."""
        value = self._single(var)
        if isinstance(value, ir.Expr) and value.op == "getattr":
            if self._resolve(value.value) is None:
                return value.value, value.attr
        return None


def _among(target: Any, group: frozenset[Any]) -> bool:
    try:
        return target is not None and target in group
    except TypeError:  # unhashable
        return False


def _call_vars(call: ir.Expr) -> list[ir.Var]:
    out = list(call.args) + [v for _, v in call.kws]
    return out + [v for v in (call.vararg, call.varkwarg) if v is not None]


def _bind(target: Any, call: ir.Expr) -> dict[int, ir.Var] | None:
    """Argument number -> variable of a call (None: not plain positional/keyword)."""
    if call.vararg is not None or call.varkwarg is not None:
        return None
    bound = dict(enumerate(call.args))
    if call.kws:
        try:
            names = list(inspect.signature(target.py_func).parameters)
        except (AttributeError, TypeError, ValueError):
            return None
        for name, var in call.kws:
            if name not in names:
                return None
            bound[names.index(name)] = var
    return bound


def _callee_reading(target: Any) -> _Reading | None:
    """The reading of a compiled callee (a Numba dispatcher), or None."""
    func = getattr(target, "py_func", None)
    if func is None or not inspect.isfunction(func):
        return None
    return _reading(func)


_READINGS: dict[Any, _Reading] = {}


def _reading(func: Callable[..., Any]) -> _Reading:
    found = _READINGS.get(func)
    if found is None:
        found = _READINGS[func] = _Reading()  # (stored first: a recursive call keeps all)
        found.read(func)
    return found
