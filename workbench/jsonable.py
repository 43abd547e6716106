"""One generic JSON serialisation of result objects (issue 35, item 3).

:func:`to_json` turns a result into plain JSON data (dict, list, str, float,
int, bool, None), recursively:

* a **dataclass** gives the dict of its fields, or, when its class declares a
  view ``JSON_FIELDS`` (a mapping ``{json key: attribute path or function}``),
  the dict of that view in its order: a path ``"synthesis.bracket.h"`` reads
  the attribute chain (``None`` part-way gives ``None``), a function is called
  with the object (and may return :data:`OMIT` to leave its key out). A
  view names what a result publishes (its JSON keys are an interface of the
  ``--json`` outputs); every conversion below stays generic;
* an **enum** gives its value;
* a **numpy array** gives nested lists, a **numpy scalar** its Python value;
* a **tuple, list or set** gives a list, a **dict** a dict (keys as given);
* a **float** stays a float, except that infinities become the strings
  ``"inf"`` and ``"-inf"`` (JSON has no infinity); NaN stays NaN unless a view
  maps it (the outputs of the workbench did so before this module, and
  their JSON is unchanged by it).

:func:`json_method` is the ``to_json`` method of a result class that has a
view: ``to_json = json_method``.

References
----------
python-control, ``TimeResponseData``: one result type, generic accessors;
cvxpy, ``Reduction``/``Chain``: one protocol instead of per-stage code.
"""
from __future__ import annotations

import dataclasses
import enum
import math
from typing import Any

import numpy as np

__all__ = ["OMIT", "to_json", "json_method", "finite_or_none"]

#: What a view function returns to leave its key out of the JSON.
OMIT = object()


def finite_or_none(x) -> float | None:
    """``float(x)`` when finite, else ``None`` (for views that publish an
    undefined or unbounded number as ``null``)."""
    return float(x) if x is not None and np.isfinite(x) else None


def _read(obj, path: str):
    for name in path.split("."):
        if obj is None:
            return None
        obj = getattr(obj, name)
    return obj


def to_json(obj: Any) -> Any:
    """Plain JSON data of ``obj`` (see the module docstring).

    Parameters
    ----------
    obj : dataclass, enum, numpy array or scalar, tuple, list, set, dict,
        str, int, float, bool or None

    Returns
    -------
    dict, list, str, int, float, bool or None

    Raises
    ------
    TypeError
        For a type it does not know (never silently ``str(obj)``).
    """
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, enum.Enum):
        return obj.value
    if isinstance(obj, int):
        return obj
    if isinstance(obj, float):
        return ("inf" if obj > 0 else "-inf") if math.isinf(obj) else obj
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return to_json(obj.item())
    if isinstance(obj, dict):
        return {k: to_json(v) for k, v in obj.items()}
    if isinstance(obj, (tuple, list, set, frozenset)):
        return [to_json(v) for v in obj]
    view = getattr(type(obj), "JSON_FIELDS", None)
    if view is not None:
        vals = ((k, f(obj) if callable(f) else _read(obj, f)) for k, f in view.items())
        return {k: to_json(v) for k, v in vals if v is not OMIT}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_json(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    raise TypeError(f"to_json: {type(obj).__name__} is not serialisable; expected a dataclass, "
                    "enum, numpy value, container or JSON scalar")


def json_method(self) -> Any:
    """``to_json`` of a result class: :func:`to_json` of the object."""
    return to_json(self)
