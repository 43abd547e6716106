"""TOML design files -> validated, typed specs.

A design file is data: parameters (each with its unit and source), settings
and claims. Every problem is a :class:`~workbench.errors.DesignError` naming
the file, the key, the value and what was expected. Nothing in a design file
is ever evaluated as code.

Layout shared by every design::

    [design]
    name = "antiskid-cruise-dry"     # = file stem
    kind = "antiskid-cruise"         # selects the study (workbench.kinds)
    title = "..."
    source = "paper 003, ..."

    [[claims]]                        # optional, see workbench.claims
    ...
    [[hazards]]                       # optional hazard log, see workbench.claims
    [[assumptions]]                   # optional assumptions register

The rest of the file belongs to the study named by ``kind``; it reads it
through a :class:`~workbench.reader.Reader`, which records which keys were used so that
unknown keys (often typos) are errors too.
"""
from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .errors import DesignError
from .reader import Reader, display_path
from .report.files import SAFE_NAME
from .toml_input import load_toml

@dataclass(frozen=True)
class Design:
    """A loaded design file.

    Attributes
    ----------
    path : str
    name, kind, title, source : str
    spec : object
        The study-specific, validated spec (frozen dataclass).
    claims : tuple
        Validated :class:`workbench.claims.Claim` objects.
    hazards, assumptions : tuple
        The design's hazard log and assumptions register
        (:class:`workbench.claims.Hazard`, :class:`workbench.claims.Assumption`).
    sha256 : str
        SHA-256 of the design file's bytes (configuration identification).
    """

    path: str
    name: str
    kind: str
    title: str
    source: str
    spec: Any
    claims: tuple
    hazards: tuple = ()
    assumptions: tuple = ()
    sha256: str = ""


#: Environment variable of the last-bit perturbation test (``make test-full``):
#: an integer k moves every physical parameter of every design k ulps.
PERTURB_ENV = "WORKBENCH_PERTURB_ULPS"


def perturbed(data: Any, ulps: int) -> Any:
    """``data`` with every float ``value`` of a physical quantity (a table
    with ``value`` and ``unit``) moved by ``ulps`` units in the last place.

    The last-bit perturbation test: a report must not change when its
    inputs move by a few ulp, as they do between CPUs (numpy's SIMD loops,
    BLAS kernels). Numerical settings (steps, tolerances, grids) and claims
    are not physical inputs and are left alone.
    """
    if isinstance(data, dict):
        out = {k: perturbed(v, ulps) for k, v in data.items()}
        v = data.get("value")
        if "unit" in data and isinstance(v, float) and math.isfinite(v) and v != 0.0:
            for _ in range(abs(ulps)):
                v = math.nextafter(v, math.copysign(math.inf, ulps))
            out["value"] = v
        return out
    if isinstance(data, list):
        return [perturbed(v, ulps) for v in data]
    return data


def load_design(path: str | Path) -> Design:
    """Load and validate a design file.

    Raises
    ------
    DesignError
        On any problem, naming file, key, value and what was expected.
    """
    shown = display_path(path)
    p = Path(path)
    if not p.is_file():
        raise DesignError(shown, "<file>", "<a folder>" if p.is_dir() else "<missing>",
                          "an existing design file (.toml)")
    data = load_toml(p, shown)
    raw = p.read_bytes()
    ulps = os.environ.get(PERTURB_ENV, "").strip()
    key = (shown, str(p.resolve()), hashlib.sha256(raw).hexdigest(), ulps)
    if key in _LOADED:
        return _LOADED[key]
    design = _validated(p, shown, data, raw, ulps)
    from . import kinds
    if not getattr(kinds.REGISTRY[design.kind], "reads_other_files", False):
        _LOADED[key] = design
    return design


#: (shown path, absolute path, SHA-256 of the bytes, perturbation) -> Design:
#: a design is validated once per process (``workbench check`` loads every
#: design in its parent, again for its verify and report phases, and its
#: forked workers inherit what the parent loaded). Only valid designs are
#: kept, and only of kinds whose spec is read from the design file alone (a
#: study with ``reads_other_files``, such as ``delay-benchmark``'s example
#: folder, is read again every time).
_LOADED: dict = {}


def _validated(p: Path, shown: str, data: dict, raw: bytes, ulps: str) -> Design:
    from . import kinds
    from .claims import parse_claims, parse_register
    if ulps:
        if not ulps.lstrip("+-").isdigit() or len(ulps) > 6:
            raise DesignError("<environment>", PERTURB_ENV, ulps[:40], "an integer number of ulps")
        data = perturbed(data, int(ulps))
    root = Reader(shown, data)
    head = root.table("design")
    name = head.string("name")
    if name != p.stem:
        raise head.fail("name", name, f'the file name without .toml, "{p.stem}"')
    if not SAFE_NAME.fullmatch(name):
        raise head.fail("name", name, "a file-name-safe name: letters, digits, '-', '_', '.', "
                        "not starting with '.' (reports are written under it)")
    kind = head.string("kind", choices=sorted(kinds.REGISTRY))
    title = head.string("title")
    source = head.string("source")
    head.finish()
    study = kinds.REGISTRY[kind]
    spec = study.load(root)
    claims = parse_claims(root, study, spec)
    hazards, assumptions = parse_register(root, claims)
    root.finish()
    return Design(shown, name, kind, title, source, spec, tuple(claims), hazards, assumptions,
                  hashlib.sha256(raw).hexdigest())
