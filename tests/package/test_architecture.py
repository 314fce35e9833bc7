"""The package's architecture, read from its sources with ``ast`` (nothing is imported).

Rules:

1. The compiled layer, ``polycontact._kernels``, imports no polycontact module outside
   itself, and of third-party packages NumPy and Numba only (and ``platformdirs`` in its
   cache locator, ``_kernels/cache.py``, which finds the per-user cache directory).
   Errors are raised by the public functions that call the kernels.
2. No import cycle among polycontact modules. Every import counts, at the top of a
   module or inside a function (a lazy import runs the module all the same); only the
   imports under ``if TYPE_CHECKING:`` are left out, since they never run. Importing
   ``polycontact.a.b`` runs the package ``polycontact.a`` first, so it counts as an
   import of that package too (``polycontact`` itself, which every import runs
   first, is not counted that way).
3. No private name crosses modules: a name with one leading underscore is neither
   imported from another module (``from .x import _y``) nor read from an imported module
   (``x._y``). Inside ``_kernels`` too: a helper that other kernel modules call belongs
   to its module's interface and is named without the underscore. A private module
   (``_checks``, ``_kernels``) may be imported: its underscore keeps it private to the
   package, and the names in it are what it offers to the package. Dunder names
   (``__version__``) are not private.
4. Kernels are decorated with ``polycontact._kernels.jit.njit`` (Numba's ``njit``,
   compiling one specialisation per kernel for read-only and writable arrays,
   constants and variables), never Numba's own: no kernel module takes ``njit`` or
   ``jit`` from ``numba``.
"""

from __future__ import annotations

import ast
import sys
from dataclasses import dataclass
from pathlib import Path

import polycontact

PACKAGE = Path(polycontact.__file__).resolve().parent
ROOT = "polycontact"
KERNELS = f"{ROOT}._kernels"
#: Third-party packages the compiled layer may import (rule 1), and where.
KERNEL_THIRD_PARTY = {"numpy": None, "numba": None, "platformdirs": {f"{KERNELS}.cache"}}


@dataclass(frozen=True)
class Import:
    """One imported thing: ``module`` (absolute), the ``name`` taken from it (None for a
    plain ``import``), the local ``alias``, the line, and whether it runs (False under
    ``if TYPE_CHECKING:``)."""

    module: str
    name: str | None
    alias: str
    line: int
    runs: bool


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = [ROOT, *path.relative_to(PACKAGE).with_suffix("").parts]
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _type_checking_lines(tree: ast.AST) -> set[int]:
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.body:
                lines.update(range(child.lineno, (child.end_lineno or child.lineno) + 1))
    return lines


def _imports(module: str) -> list[Import]:
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    hidden = _type_checking_lines(tree)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        runs = node.lineno not in hidden if hasattr(node, "lineno") else True
        if isinstance(node, ast.Import):
            out += [Import(a.name, None, a.asname or a.name.partition(".")[0], node.lineno, runs)
                    for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            out += [Import(source, a.name, a.asname or a.name, node.lineno, runs)
                    for a in node.names]
    return out


def _targets(imp: Import) -> list[str]:
    """The polycontact modules an import runs: the module named (``from a import b``
    names module ``a.b`` when there is one), and the packages that enclose it."""
    if not imp.module.startswith(ROOT):
        return []
    named = imp.module
    if imp.name is not None and f"{imp.module}.{imp.name}" in MODULES:
        named = f"{imp.module}.{imp.name}"
    parts = named.split(".")
    return [m for k in range(2, len(parts) + 1) if (m := ".".join(parts[:k])) in MODULES]


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_the_compiled_layer_imports_only_numpy_numba_and_itself():
    wrong = []
    for module in MODULES:
        if not (module == KERNELS or module.startswith(f"{KERNELS}.")):
            continue
        for imp in _imports(module):
            top = imp.module.partition(".")[0]
            if top == ROOT:
                if not (imp.module == KERNELS or imp.module.startswith(f"{KERNELS}.")):
                    wrong.append(f"{module}:{imp.line} imports {imp.module}")
            elif top not in sys.stdlib_module_names:
                allowed = KERNEL_THIRD_PARTY.get(top, set())
                if allowed is not None and module not in allowed:
                    wrong.append(f"{module}:{imp.line} imports {imp.module}")
    assert not wrong, "\n".join(wrong)


def _graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for module in MODULES:
        for imp in _imports(module):
            if not imp.runs:
                continue
            for target in _targets(imp):
                # (a module's own packages are running already when it is imported)
                if target != module and not module.startswith(f"{target}."):
                    graph[module].add(target)
    return graph


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle, as the list of modules around it, or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        path.append(m)
        for n in sorted(graph[m]):
            if state.get(n) == 1:
                return path[path.index(n):] + [n]
            if n not in state and (found := visit(n)) is not None:
                return found
        path.pop()
        state[m] = 2
        return None

    for m in sorted(graph):
        if m not in state and (found := visit(m)) is not None:
            return found
    return None


def test_no_import_cycle_counting_imports_inside_functions():
    cycle = _cycle(_graph())
    assert cycle is None, " -> ".join(cycle or [])


def test_no_private_name_is_imported_across_modules():
    wrong = []
    for module, path in MODULES.items():
        aliases = {}
        for imp in _imports(module):
            if not imp.module.startswith(ROOT):
                continue
            if imp.name is not None and _private(imp.name):
                wrong.append(f"{module}:{imp.line} imports {imp.name} from {imp.module}")
            target = imp.module if imp.name is None else f"{imp.module}.{imp.name}"
            if target in MODULES:
                aliases[imp.alias] = target
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in aliases and _private(node.attr)):
                wrong.append(f"{module}:{node.lineno} reads {node.attr} of "
                             f"{aliases[node.value.id]}")
    assert not wrong, "\n".join(wrong)


def test_kernels_take_njit_from_the_kernels_decorator_module():
    wrong = []
    for module in MODULES:
        if not module.startswith(f"{KERNELS}.") or module == f"{KERNELS}.jit":
            continue
        for imp in _imports(module):
            if imp.module.partition(".")[0] == "numba" and imp.name in ("njit", "jit"):
                wrong.append(f"{module}:{imp.line} takes {imp.name} from numba: "
                             f"take njit from {KERNELS}.jit")
    assert not wrong, "\n".join(wrong)


def test_the_rules_see_what_they_are_about():
    """The checks above read something: the modules, a lazy import inside a function,
    and the imports the public side makes of the kernels."""
    assert f"{KERNELS}.cache" in MODULES and f"{ROOT}.relation" in MODULES
    graph = _graph()
    assert f"{ROOT}.relation" in graph[f"{ROOT}.compiling"]  # (inside warmup's helper)
    assert KERNELS in graph[f"{ROOT}.relation"]
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
