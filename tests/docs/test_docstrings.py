"""Docstrings of the public API in one order: summary, Parameters, Returns,
Raises, Examples, then Notes (proofs and derivations) last, so that ``help()`` shows
how to call a function before why it works."""

from __future__ import annotations

import inspect
import re

import polycontact as pc
from polycontact import plotting, shape

ORDER = ["Parameters", "Attributes", "Returns", "Yields", "Raises", "Warns", "See Also",
         "Examples", "Notes", "References"]


def _sections(doc: str) -> list[str]:
    lines = inspect.cleandoc(doc).splitlines()
    return [lines[i].strip() for i in range(1, len(lines) - 1)
            if re.fullmatch(r"-{3,}", lines[i + 1].strip()) and lines[i].strip()]


def _public() -> dict[str, object]:
    found: dict[str, object] = {"shape.as_shape": shape.as_shape}
    for name in pc.__all__:
        obj = getattr(pc, name)
        found[name] = obj
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if not member.startswith("_"):
                    found[f"{name}.{member}"] = getattr(value, "fget",
                                                        getattr(value, "func", value))
    for name in plotting.__all__:
        found[f"plotting.{name}"] = getattr(plotting, name)
    return found


def test_public_docstrings_have_their_sections_in_order():
    wrong = {}
    for name, obj in _public().items():
        doc = getattr(obj, "__doc__", None)
        if not isinstance(doc, str):
            continue
        sections = _sections(doc)
        if any(s not in ORDER for s in sections) or sections != sorted(sections, key=ORDER.index):
            wrong[name] = sections
    assert not wrong


def test_time_of_impact_help_starts_with_how_to_call_it():
    lines = inspect.getdoc(pc.time_of_impact).splitlines()
    assert lines.index("Parameters") < 12 and lines.index("Notes") > lines.index("Examples")
    t_max = lines[lines.index("t_max : float") + 1]
    assert "End of the time window" in t_max and "time unit" in t_max
