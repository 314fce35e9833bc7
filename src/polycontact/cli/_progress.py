"""Long work says so: a step still running after a few seconds prints one line on
stderr, and how long it took when it ends (never on stdout, so ``--json`` stays
parseable).

The delay is :data:`polycontact.limits.NOTICE_AFTER` seconds, or the environment variable
``POLYCONTACT_NOTICE_AFTER`` (a number of seconds; ``inf`` silences the notices, ``0``
prints them at once, before the step).

>>> isinstance(notice_delay(), float)
True
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

from ..limits import NOTICE_AFTER
from ._errors import CommandError

__all__ = ["announced", "notice_delay", "progress_line"]

_VARIABLE = "POLYCONTACT_NOTICE_AFTER"


def notice_delay() -> float:
    """The delay before a notice: ``POLYCONTACT_NOTICE_AFTER`` if set, else
    :data:`polycontact.limits.NOTICE_AFTER`; a :class:`CommandError` if the variable is
    not a number >= 0."""
    text = os.environ.get(_VARIABLE)
    if text is None:
        return NOTICE_AFTER
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value >= 0.0:
        raise CommandError(f"{_VARIABLE}: expected a number of seconds >= 0 (inf: no "
                           f"notices), got {text!r}")
    return value


def _say(line: str) -> None:
    try:
        print(f"polycontact: {line}", file=sys.stderr, flush=True)
    except (OSError, ValueError):  # stderr closed: nothing to tell
        pass


@contextmanager
def announced(what: str) -> Iterator[None]:
    """Run the ``with`` block; if it still runs after :func:`notice_delay` seconds, say
    ``polycontact: {what} ...`` on stderr, and at its end ``{what}: done in N s``.

    ``what`` names the step and its size (``"classifying a.json (2000000 vertices) and
    b.json (4 vertices)"``); the notice comes from a timer thread, so it shows while
    compiled code or GEOS (which release the GIL) or Python code works.
    """
    delay = notice_delay()
    lock = threading.Lock()
    state = {"said": False, "over": False}

    def notice() -> None:
        with lock:
            if not state["over"]:
                state["said"] = True
                _say(f"{what} ...")

    timer = None
    if delay <= 0.0:
        notice()
    elif math.isfinite(delay):
        timer = threading.Timer(delay, notice)
        timer.daemon = True
        timer.start()
    t0 = time.perf_counter()
    ok = False
    try:
        yield
        ok = True
    finally:
        if timer is not None:
            timer.cancel()
        with lock:
            state["over"] = True
            if state["said"] and ok:
                _say(f"{what}: done in {time.perf_counter() - t0:.1f} s")


def progress_line(family: str, k: int, n: int, seconds: float | None) -> None:
    """One stderr line per stage of :func:`polycontact.compiling.warmup`."""
    if seconds is None:
        print(f"  [{k}/{n}] {family} ...", end="", file=sys.stderr, flush=True)
    else:
        print(f" {seconds:.1f} s", file=sys.stderr, flush=True)
