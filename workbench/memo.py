"""Each study result computed once per process, and how long it took.

``workbench check`` (verify, then the report check) and the test session
evaluate the same designs more than once in one process. :func:`run_study`
runs a design's study the first time and hands back that same result for
any later design with an equal spec (the study's input: its ``run`` reads
nothing else of the design). Results are frozen dataclasses, and report
rendering is pure, so sharing one is the same as recomputing it.

By default nothing is kept across processes and nothing is written to disk:
every ``workbench`` command and every test session computes each study
afresh, once. A *run folder* shares results between the processes of one
run: with ``WORKBENCH_STUDY_CACHE=DIR`` set (``make test`` sets it to a new
temporary folder, filled by ``workbench check --jobs N`` and read by the
test session after it), a result is pickled to ``DIR`` under a hash of the
package's source, the study function and the exact spec key, and a later
process of the same run loads it instead of computing it again. The folder
belongs to one run of one source tree: the source hash in every name keeps a
result from being read by other code.

:func:`start_studies` starts the parts of studies that run in worker
processes ahead of time (``workbench check`` starts the Monte Carlo pools
first, so they run while the other designs are checked).

:func:`study_times` is the timing hook: wall and CPU seconds (this
process) of every study that ran.
"""
from __future__ import annotations

import dataclasses
import enum
import math
import os
import time
from dataclasses import dataclass
from pathlib import PurePath
from typing import Any, Callable

@dataclass(frozen=True)
class StudyTime:
    """One study run: the design that asked for it and its cost.

    Attributes
    ----------
    design : str
        Design name (its file stem).
    kind : str
        Study kind.
    wall, cpu : float
        Seconds of the study's ``run`` in this process; ``cpu`` is user +
        system time of this process only (the Monte Carlo pools' workers
        are not in it).
    since_start : float or None
        For a study whose worker processes :func:`start_studies` started
        early: wall seconds from that start to its result (they include
        whatever this process did in between); None otherwise.
    """

    design: str
    kind: str
    wall: float
    cpu: float
    since_start: float | None = None


_RESULTS: dict[tuple, Any] = {}
_TIMES: list[StudyTime] = []
_STARTED: dict[tuple, tuple] = {}     # key -> (study, handle, wall clock, cpu) at start


class _Unkeyable(Exception):
    pass


def _key(x: Any) -> Any:
    """A hashable, exact image of a spec (floats by value, arrays by bytes);
    raises :class:`_Unkeyable` on a type it does not know (then no sharing)."""
    if x is None or isinstance(x, (bool, int, str)):
        return (type(x).__name__, x)
    if isinstance(x, float):
        return ("float", x.hex() if math.isfinite(x) else repr(x))
    if isinstance(x, enum.Enum):
        return (type(x).__qualname__, _key(x.value))
    if isinstance(x, PurePath):
        return ("path", str(x))
    if isinstance(x, (tuple, list)):
        return (type(x).__name__, tuple(_key(v) for v in x))
    if isinstance(x, (set, frozenset)):
        return ("set", tuple(sorted(_key(v) for v in x)))
    if isinstance(x, dict):
        return ("dict", tuple(sorted((_key(k), _key(v)) for k, v in x.items())))
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return (type(x).__module__, type(x).__qualname__,
                tuple((f.name, _key(getattr(x, f.name))) for f in dataclasses.fields(x)))
    import numpy as np
    if isinstance(x, np.ndarray):
        if x.dtype.hasobject:
            return ("ndarray-object", x.shape, tuple(_key(v) for v in x.ravel().tolist()))
        return ("ndarray", x.dtype.str, x.shape, np.ascontiguousarray(x).tobytes())
    if isinstance(x, np.generic):
        return (type(x).__name__, _key(x.item()))
    raise _Unkeyable(type(x).__qualname__)


def spec_key(x: Any) -> Any:
    """A hashable, exact key of ``x`` (a spec or part of one), or None when
    ``x`` holds a type this module cannot key exactly (then: do not share)."""
    try:
        return _key(x)
    except (_Unkeyable, TypeError):
        return None


def _cpu() -> float:
    t = os.times()
    return t.user + t.system


def _design_key(design) -> tuple | None:
    spec = spec_key(design.spec)
    return None if spec is None else (design.kind, spec)


def start_studies(designs, registry) -> None:
    """Start now the parts of these designs' studies that run in worker
    processes (studies with a ``start(design)`` method: the Monte Carlo
    pools of ``antiskid-run``), so that they overlap the other designs;
    :func:`run_study` hands the handle to the study's ``run``. Call
    :func:`cancel_started` when leaving early."""
    for d in designs:
        key, study = _design_key(d), registry[d.kind]
        if key is None or key in _RESULTS or key in _STARTED or not hasattr(study, "start"):
            continue
        w0 = time.perf_counter()
        handle = study.start(d)
        if handle is not None:           # nothing started: timed from its run, as any other
            _STARTED[key] = (study, handle, w0)


def cancel_started() -> None:
    """Stop the worker processes of started studies that never ran."""
    while _STARTED:
        _, (_, handle, _) = _STARTED.popitem()
        for p in handle or ():
            if p is not None:
                p.cancel()


#: Environment variable naming the run folder of shared study results.
CACHE_ENV = "WORKBENCH_STUDY_CACHE"
_SOURCE_HASH: list[str] = []


def _source_hash() -> str:
    """SHA-256 of every module of the package (computed once per process)."""
    if not _SOURCE_HASH:
        import hashlib
        from pathlib import Path
        root = Path(__file__).resolve().parent
        h = hashlib.sha256()
        for f in sorted(root.rglob("*.py")):
            h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
        _SOURCE_HASH.append(h.hexdigest())
    return _SOURCE_HASH[0]


def _cache_file(key, run):
    """The run folder's file of (key, run), or None (no folder, or a run
    function without a stable name such as a lambda)."""
    name = f"{getattr(run, '__module__', '')}.{getattr(run, '__qualname__', '')}"
    if key is None or "<" in name:
        return None
    return shared_file(name, key)


def shared_file(name: str, key):
    """The run folder's file for the result named ``name`` with exact key
    ``key`` (see the module docstring), or None when no run folder is set."""
    folder = os.environ.get(CACHE_ENV)
    if not folder:
        return None
    import hashlib
    from pathlib import Path
    digest = hashlib.sha256(f"{_source_hash()}|{name}|{key!r}".encode()).hexdigest()
    return Path(folder) / f"{digest}.pickle"


def shared(name: str, key, compute: Callable[[], Any]) -> Any:
    """``compute()``, or its result left in the run folder by an earlier
    process of the same run (``key`` must determine the result exactly)."""
    path = shared_file(name, key)
    if path is not None and path.is_file():
        found, result = _load(path)
        if found:
            return result
    result = compute()
    if path is not None:
        _store(path, result)
    return result


def computed_once(name: str, key, compute: Callable[[], Any]) -> Any:
    """:func:`shared`, and kept in this process too (forgotten by :func:`clear`)."""
    mine = ("computed_once", name, key)
    if mine not in _RESULTS:
        _RESULTS[mine] = shared(name, key, compute)
    return _RESULTS[mine]


def _load(path):
    import pickle
    try:
        with open(path, "rb") as f:
            return True, pickle.load(f)
    except (OSError, EOFError, pickle.UnpicklingError, AttributeError, ImportError):
        return False, None


def _store(path, result) -> None:
    """Pickle ``result`` to ``path`` atomically (a result that does not pickle
    is simply not shared)."""
    import pickle
    import tempfile
    try:
        data = pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:            # closures, locks: not shareable, compute again
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".", suffix=".tmp")
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def run_study(design, run: Callable[..., Any]) -> Any:
    """``run(design)``, computed once per process for an equal (kind, spec).

    Parameters
    ----------
    design : workbench.design.Design
    run : callable
        The study's ``run``; called as ``run(design, started=handle)`` when
        :func:`start_studies` started the design.
    """
    key = _design_key(design)
    if key is not None and key in _RESULTS:
        return _RESULTS[key]
    shared = _cache_file(key, run)
    if shared is not None and shared.is_file():
        found, result = _load(shared)
        if found:
            _RESULTS[key] = result
            return result
    w0, c0, started = time.perf_counter(), _cpu(), None
    if key is not None and key in _STARTED:
        _, handle, started = _STARTED.pop(key)
        result = run(design, started=handle)
    else:
        result = run(design)
    w1 = time.perf_counter()
    _TIMES.append(StudyTime(design.name, design.kind, w1 - w0, _cpu() - c0,
                            None if started is None else w1 - started))
    if key is not None:
        _RESULTS[key] = result
    if shared is not None:
        _store(shared, result)
    return result


def study_times() -> tuple[StudyTime, ...]:
    """Every study run of this process so far, in order (shared results are
    not repeated)."""
    return tuple(_TIMES)


def clear() -> None:
    """Forget every result and time, and stop what was started (tests)."""
    cancel_started()
    _RESULTS.clear()
    _TIMES.clear()
