"""The README's Python examples (blocks with ``>>>``) run and print what it says."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[2] / "README.md"
BLOCKS = [
    m.group(1)
    for m in re.finditer(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    if ">>>" in m.group(1)
]


def test_readme_has_examples():
    assert len(BLOCKS) >= 3


def test_readme_examples_in_order():
    """Blocks run in order in one namespace, as a reader typing them would."""
    parser = doctest.DocTestParser()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    names: dict = {"np": np}
    for index, block in enumerate(BLOCKS):
        test = parser.get_doctest(block, names, f"README block {index}", str(README), 0)
        test.globs = names  # keep what earlier blocks defined
        runner.run(test, clear_globs=False)
    assert runner.failures == 0, "a README example fails (see the output above)"
