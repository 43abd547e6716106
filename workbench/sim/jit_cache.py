"""A disk cache for the compiled (numba) kernels, shared by every process of a machine.

numba's own cache (``numba.njit(cache=True)``) cannot hold the antiskid
kernels: their model functions are ``sympy.lambdify`` output and their
wrappers are generated with ``exec`` (no source file for numba's locators),
and the kernels are closures over other compiled functions, whose pickled
form carries a per-process id, so numba's index key never matches in a
later process. This module gives such a function a cache of its own:

* **where**: ``$WORKBENCH_CACHE_DIR`` if set, else
  ``$XDG_CACHE_HOME/workbench`` (``~/.cache/workbench``), in
  ``numba/<stamp>/`` under it;
* **what invalidates it**: the stamp, a SHA-256 of the text of every
  ``.py`` file of the ``workbench`` package (which holds every equation,
  constant and generated source that a kernel compiles: the sympy model is
  written in ``plants/``, the settings layout in ``controllers/``), with
  the versions of Python, numba, llvmlite, numpy and sympy. Any change of
  either gives a new directory; stale directories are never read (they may
  be deleted at any time). Within a directory numba's index keys each
  entry by the signature, the target CPU and its features
  (``codegen.magic_tuple()``) and the function's bytecode, so a cache
  directory shared by different machines serves each its own code;
* **concurrency**: numba writes every file under a unique temporary name
  and renames it into place (:meth:`numba.core.caching.IndexDataCacheFile._open_for_write`),
  so processes that compile the same kernel at once would each write a
  complete file and the last rename wins (both are the same code). They do
  not compile it at once: a process that misses the cache takes an
  exclusive ``flock`` on ``<name>.lock`` in the directory, looks again
  (another process may have written the kernel while it waited) and only
  then compiles, releasing the lock once the kernel is saved (or when the
  process ends, if the compilation failed). Two workers of ``workbench
  check --jobs 2`` that start the antiskid runs together thus compile each
  kernel once (about 20 CPU-s each, issue 36): the second loads it.

A loaded kernel is the machine code the first process compiled, so its
results are bit-identical to compiling it again on the same machine.
``WORKBENCH_NUMBA_CACHE=0`` turns the cache off (every process compiles);
an unwritable cache directory does too.

This relies on numba's cache classes (``numba.core.caching``; the stamp
includes numba's version, so a numba upgrade starts a new directory).
"""
from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

__all__ = ["cache_dir", "cached", "require_numba", "source_stamp"]


@lru_cache(maxsize=None)
def source_stamp() -> str:
    """SHA-256 (hex) of the ``workbench`` package's ``.py`` files (path
    and text, in path order) and of the Python, numba, llvmlite, numpy and
    sympy versions: the key of :func:`cache_dir`."""
    import llvmlite
    import numba
    import numpy
    import sympy
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for v in (sys.version, numba.__version__, llvmlite.__version__, numpy.__version__,
              sympy.__version__):
        h.update(v.encode() + b"\0")
    for f in sorted(root.rglob("*.py")):
        h.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()


def cache_dir() -> Path | None:
    """The directory of this source's compiled kernels (module docstring),
    created if needed; None when the cache is off or not writable."""
    if os.environ.get("WORKBENCH_NUMBA_CACHE", "1") == "0":
        return None
    return _writable_dir(os.environ.get("WORKBENCH_CACHE_DIR", ""),
                         os.environ.get("XDG_CACHE_HOME", ""))


@lru_cache(maxsize=None)
def _writable_dir(explicit: str, xdg: str) -> Path | None:
    try:
        base = Path(explicit) if explicit else Path(xdg or Path.home() / ".cache") / "workbench"
        d = base / "numba" / source_stamp()[:32]
        d.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=d):
            pass
    except (OSError, RuntimeError):     # RuntimeError: no home directory
        return None
    return d


@lru_cache(maxsize=None)
def _cache_class():
    """The numba cache class bound to :func:`cache_dir` (built on first use:
    importing numba is slow)."""
    from numba.core.caching import CompileResultCacheImpl, FunctionCache, IndexDataCacheFile

    class Locator:
        def __init__(self, path: Path, name: str, py_file: str):
            self._path, self._name, self._py_file = str(path), name, py_file

        def ensure_cache_path(self):
            os.makedirs(self._path, exist_ok=True)

        def get_cache_path(self):
            return self._path

        def get_source_stamp(self):
            return source_stamp()

        def get_disambiguator(self):
            return self._name

    class Impl(CompileResultCacheImpl):
        def __init__(self, py_func, name: str, path: Path):   # numba's, with our locator
            self._lineno = py_func.__code__.co_firstlineno
            self._locator = Locator(path, name, py_func.__code__.co_filename)
            self._filename_base = self.get_filename_base("workbench", getattr(sys, "abiflags", ""))

    class Cache(FunctionCache):
        def __init__(self, py_func, name: str, path: Path):   # as numba's Cache.__init__
            self._name, self._py_func = f"{name} ({py_func!r})", py_func
            self._lock_name, self._held = name, None
            self._impl = Impl(py_func, name, path)
            self._cache_path = str(path)
            self._cache_file = IndexDataCacheFile(cache_path=self._cache_path,
                                                  filename_base=self._impl.filename_base,
                                                  source_stamp=source_stamp())
            self.enable()

        def _index_key(self, sig, codegen):
            # no closure contents: the stamp covers what they are built from
            code = hashlib.sha256(self._py_func.__code__.co_code).hexdigest()
            return sig, codegen.magic_tuple(), code

        def load_overload(self, sig, target_context):
            # a miss: wait for a process compiling it now, look again; the
            # lock stays held through this process's compilation (module docstring)
            self._release()
            got = super().load_overload(sig, target_context)
            if got is None:
                self._held = _lock(Path(self._cache_path) / f"{self._lock_name}.lock")
                got = super().load_overload(sig, target_context)
                if got is not None:
                    self._release()
            return got

        def save_overload(self, sig, data):
            try:
                super().save_overload(sig, data)
            finally:
                self._release()

        def _release(self):
            fd, self._held = getattr(self, "_held", None), None
            if fd is not None:
                fd.close()          # closing the file releases its flock

    return Cache


def _lock(path: Path):
    """An open file holding an exclusive ``flock`` on ``path`` (blocks until
    granted); None where locking is unavailable (the cache still works, a
    kernel may then be compiled by two processes at once)."""
    try:
        import fcntl
        fd = open(path, "a")
    except (ImportError, OSError):
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
    except OSError:
        fd.close()
        return None
    return fd


_NAMES: dict[str, bytes] = {}    # cache name -> bytecode


def cached(dispatcher, name: str):
    """``dispatcher`` (a ``numba.njit`` function) with its compilations kept
    in :func:`cache_dir` under ``name`` (unique per compiled function: two
    functions may share bytecode); returns ``dispatcher``. Without a cache
    directory it compiles as before."""
    if _NAMES.setdefault(name, dispatcher.py_func.__code__.co_code) != \
            dispatcher.py_func.__code__.co_code:
        raise RuntimeError(f"two compiled functions share the cache name {name!r}")
    d = cache_dir()
    if d is not None:
        dispatcher._cache = _cache_class()(dispatcher.py_func, name, d)
    return dispatcher


def require_numba(what: str) -> None:
    """Raise :class:`~workbench.errors.ModelError` naming ``what`` (the
    computation that runs compiled code) when numba is not installed."""
    from importlib.util import find_spec
    if find_spec("numba") is None:
        from ..errors import ModelError
        raise ModelError(f"{what} runs a compiled loop, which needs numba: "
                         "pip install 'traincontrol-workbench[fast]'")
