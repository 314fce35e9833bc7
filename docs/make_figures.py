"""Make the gallery's figures by running the shipped examples (called by conf.py).

    python docs/make_figures.py docs/_figures
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: (figure file, command, example files, options): what a user runs for the same figure.
FIGURES = [
    ("impact-paper-case-1.png", "collide", ["paper-case-1.json"], []),
    # The paper's printed coordinates (rounded to 0.01) make red cross itself once.
    ("impact-paper-case-2.png", "collide", ["paper-case-2.json"], ["--repair"]),
    ("entrance-block-ell-frame.png", "entrance-block", ["body-ell.json", "body-frame.json"], []),
    ("nfp-cavity.png", "nfp", ["nfp-square.json", "nfp-cavity.json"], []),
    ("nfp-slot.png", "nfp", ["nfp-square.json", "nfp-slot.json"], []),
    ("nfp-dovetail.png", "nfp", ["nfp-dovetail-a.json", "nfp-dovetail-b.json"], []),
    ("contacts-layout.png", "contacts", ["layout.json"], []),
]


#: Text sizes for figures shown at the width of a page's text column (about 900 px,
#: where the command line's own figures are 1100-1350 px wide): larger than
#: matplotlib's defaults, so that legends and labels stay readable once scaled down;
#: saved with a tight bounding box, so that no legend or label is cut at the edge.
READABLE = {"font.size": 15, "axes.titlesize": 16, "axes.labelsize": 15,
            "xtick.labelsize": 13, "ytick.labelsize": 13, "savefig.bbox": "tight",
            "savefig.pad_inches": 0.1}

#: (figure file, example script, its options): figures the examples draw themselves.
SCRIPTS = [("dem-hopper.png", "dem_hopper.py", [])]


def main(out: Path) -> None:
    """Write every figure of :data:`FIGURES` and :data:`SCRIPTS` into ``out`` (a
    directory)."""
    import contextlib
    import io

    import matplotlib

    from polycontact.cli import main as cli

    out.mkdir(parents=True, exist_ok=True)
    for name, command, files, options in FIGURES:
        args = [command, *(str(EXAMPLES / f) for f in files), *options, "--plot", str(out / name)]
        with contextlib.redirect_stdout(io.StringIO()), matplotlib.rc_context(READABLE):
            status = cli(args)
        if status != 0:
            raise RuntimeError(f"polycontact {' '.join(args)} exited with {status}")
    import runpy

    for name, script, options in SCRIPTS:
        example = runpy.run_path(str(EXAMPLES / script))
        with contextlib.redirect_stdout(io.StringIO()):
            example["main"]([*options, "--out", str(out / name)])


if __name__ == "__main__":
    main(Path(sys.argv[1]))
