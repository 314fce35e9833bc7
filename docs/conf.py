"""Sphinx configuration: the reference documentation of polycontact.

Build with ``sphinx-build -W -b html docs docs/_build/html`` (CI does, warnings as
errors). The gallery's figures are made at build time by running the shipped examples
(``docs/make_figures.py``), so they always show what the code draws now.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import polycontact  # noqa: E402

project = "polycontact"
author = "the polycontact developers"
copyright = "2026, the polycontact developers"  # noqa: A001 - Sphinx's name
release = version = polycontact.__version__

extensions = ["sphinx.ext.autodoc", "numpydoc", "sphinx.ext.intersphinx"]
autodoc_typehints = "none"          # numpydoc's Parameters section carries the types
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()
intersphinx_mapping: dict[str, tuple[str, None]] = {}
exclude_patterns = ["_build"]
html_theme = "alabaster"
# A wider page and text column than alabaster's defaults (940 and 800 px), so that code
# and figures are readable; _static/custom.css (loaded by alabaster) styles the links,
# wraps long code lines and fits the figures to the text.
html_theme_options = {"page_width": "1180px", "body_max_width": "none",
                      "sidebar_width": "230px"}
html_static_path = ["_static"]
os.environ.setdefault("MPLBACKEND", "Agg")


def _figures(app: object) -> None:
    import make_figures

    make_figures.main(HERE / "_figures")


def setup(app: object) -> None:
    app.connect("builder-inited", _figures)  # type: ignore[attr-defined]
