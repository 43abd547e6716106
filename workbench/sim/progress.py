"""Progress bars of long loops (tqdm), on stderr, only for a person at a terminal.

:func:`progress` shows a bar with the count, the rate and the ETA when it is
enabled *and* stderr is a terminal; otherwise (``--json``, CI, a pipe, a
log file) it shows nothing and costs nothing. stdout is never touched, so
the commands' results stay clean.
"""
from __future__ import annotations

import sys
from typing import Iterable


def shown(enabled: bool = True, stream=None) -> bool:
    """Whether a bar would be shown: ``enabled`` and the stream (default
    stderr) is a terminal."""
    stream = sys.stderr if stream is None else stream
    return bool(enabled) and hasattr(stream, "isatty") and stream.isatty()


def progress(iterable: Iterable | None = None, *, total: int | None = None, desc: str = "",
             unit: str = "it", enabled: bool = True):
    """A ``tqdm`` bar over ``iterable`` (or updated by hand, ``total`` steps),
    on stderr, disabled unless :func:`shown`.

    Parameters
    ----------
    iterable : iterable, optional
    total : int, optional
        Number of ``unit`` to expect (for the ETA).
    desc, unit : str
        Label and unit ("run", "design", ...): the rate is shown as unit/s.
    enabled : bool
        False: silent (e.g. ``--json``).
    """
    from tqdm import tqdm
    return tqdm(iterable, total=total, desc=desc, unit=unit, file=sys.stderr,
                disable=not shown(enabled), dynamic_ncols=True, leave=True)
