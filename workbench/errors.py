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
        shown = value if isinstance(value, str) and value.startswith("<") else repr(value)
        super().__init__(f"{path}: {key} = {shown}; expected {expected}")


class ModelError(WorkbenchError, ValueError):
    """A model cannot be evaluated as asked (e.g. no cruise equilibrium)."""
