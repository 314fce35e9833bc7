"""The documentation's examples (``>>>`` lines of docs/*.rst) run and print what the
pages say, each page in one namespace, top to bottom, as a reader would type them."""

from __future__ import annotations

import doctest
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"
PAGES = sorted(p for p in DOCS.glob("*.rst") if ">>>" in p.read_text())


def test_the_documentation_has_examples():
    assert {p.stem for p in PAGES} >= {"quickstart", "guide"}


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_page_examples(page):
    test = doctest.DocTestParser().get_doctest(page.read_text(), {}, page.stem, str(page), 0)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert test.examples and runner.failures == 0, f"an example of {page.name} fails (above)"
