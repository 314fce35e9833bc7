"""The documentation's layout: a quick start first, links that look like links, code that
stays on the page, figures that fit the text with text large enough to read there.

These read the sources Sphinx builds from (the stylesheet, the configuration, the
gallery's figure settings), so they need neither Sphinx nor a build.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _css_rules() -> dict[str, str]:
    """Selector -> declarations of docs/_static/custom.css (comments dropped)."""
    text = re.sub(r"/\*.*?\*/", "", (DOCS / "_static" / "custom.css").read_text(), flags=re.S)
    rules: dict[str, str] = {}
    for selectors, body in re.findall(r"([^{}]+)\{([^}]*)\}", text):
        for selector in selectors.split(","):
            rules[" ".join(selector.split())] = rules.get(" ".join(selector.split()), "") + body
    return rules


def _declares(rules: dict[str, str], selector: str, prop: str, value: str) -> bool:
    return re.search(rf"(^|;)\s*{re.escape(prop)}\s*:\s*{re.escape(value)}\s*(;|$)",
                     rules.get(selector, "")) is not None


def test_the_quick_start_is_the_first_page_after_the_index():
    index = (DOCS / "index.rst").read_text()
    toctree = index.split(".. toctree::", 1)[1]
    pages = [line.strip() for line in toctree.splitlines()[1:]
             if line.strip() and not line.strip().startswith(":")]
    assert pages[0] == "quickstart"
    assert ":doc:`quickstart`" in index.split(".. toctree::", 1)[0]


def test_the_stylesheet_is_loaded_by_the_theme():
    conf = (DOCS / "conf.py").read_text()
    # alabaster loads _static/custom.css by itself; another theme would need html_css_files
    assert re.search(r'^html_theme = "alabaster"', conf, flags=re.M)
    assert re.search(r'^html_static_path = \["_static"\]', conf, flags=re.M)


def test_links_are_underlined_not_bold():
    rules = _css_rules()
    assert _declares(rules, "a", "text-decoration", "underline")
    assert _declares(rules, "a.reference", "text-decoration", "underline")
    assert _declares(rules, "code.xref", "font-weight", "normal")


def test_long_code_lines_wrap_instead_of_running_off_the_page():
    rules = _css_rules()
    assert _declares(rules, "pre", "white-space", "pre-wrap")
    assert _declares(rules, "pre", "overflow-wrap", "anywhere")


def test_figures_fit_the_width_of_the_text():
    assert _declares(_css_rules(), "div.body img", "max-width", "100%")


def test_gallery_figures_have_text_large_enough_at_page_width():
    sys.path.insert(0, str(DOCS))
    try:
        make_figures = pytest.importorskip("make_figures")
    finally:
        sys.path.remove(str(DOCS))
    readable = make_figures.READABLE
    # matplotlib's default is 10 pt; figures 1100-1350 px wide shown at about 900 px
    # need at least 1.3 times that for legends and labels to stay legible
    assert readable["font.size"] >= 13
    for key in ("axes.titlesize", "axes.labelsize", "xtick.labelsize", "ytick.labelsize"):
        assert readable[key] >= 12, key
    assert readable["savefig.bbox"] == "tight"  # no legend or label cut at the edge
