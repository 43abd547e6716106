"""Exceptions of the workbench.

Following python-control's ``exception.py``: one exception per kind of
failure, with messages that say what was expected and what was found.
"""
from __future__ import annotations


class WorkbenchError(Exception):
    """Base class of all workbench errors."""


class DesignError(WorkbenchError, ValueError):
    """A design file (or a CLI argument) is malformed.

    The message always names the file, the key, the value found and what
    was expected, e.g. ``designs/x.toml: plant.m = -5.0; expected a positive
    number (kg)``.

    Parameters
    ----------
    path : str
        File the problem was found in (or ``"<cli>"`` for arguments).
    key : str
        Dotted key of the offending entry.
    value : object
        The value found (``"<missing>"`` when absent).
    expected : str
        What was expected, in plain words.
    """

    def __init__(self, path: str, key: str, value: object, expected: str):
        self.path, self.key, self.value, self.expected = path, key, value, expected
        shown = value if isinstance(value, str) and value.startswith("<") else _shown(value)
        super().__init__(f"{path}: {key} = {shown}; expected {expected}")


#: Longest value shown in a message (characters); longer ones are cut.
MAX_SHOWN = 200


def _shown(value: object) -> str:
    """``repr(value)`` cut to :data:`MAX_SHOWN` characters, one line; deeply
    nested values through :mod:`reprlib` (no recursion limit is reached)."""
    import reprlib
    r = reprlib.Repr()
    r.maxlevel, r.maxstring, r.maxother = 4, MAX_SHOWN, MAX_SHOWN
    r.maxlist = r.maxtuple = r.maxdict = r.maxset = 12
    try:
        text = repr(value) if _flat(value) else r.repr(value)
    except (RecursionError, ValueError):   # ValueError: an int past the digit limit
        text = f"<{type(value).__name__}>"
    text = text.replace("\n", "\\n")
    return text if len(text) <= MAX_SHOWN else \
        f"{text[:MAX_SHOWN]}... ({len(text)} characters)"


def _flat(value: object) -> bool:
    """True when ``value`` is small enough to repr in full (at most 2 levels,
    at most 1000 items)."""
    if not isinstance(value, (list, tuple, dict, set)):
        return not isinstance(value, int) or value.bit_length() < 10_000
    items = list(value.values() if isinstance(value, dict) else value)
    return len(items) <= 1000 and all(
        not isinstance(v, (list, tuple, dict, set)) or
        (len(v) <= 1000 and not any(isinstance(w, (list, tuple, dict, set))
                                    for w in (v.values() if isinstance(v, dict) else v)))
        for v in items)


class ModelError(WorkbenchError, ValueError):
    """A model cannot be evaluated as asked (e.g. no cruise equilibrium)."""
