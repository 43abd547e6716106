"""Reading a TOML file a user wrote: limits checked before and after parsing.

``tomllib`` recurses once per level of nested arrays and inline tables, so a
file of 10 000 ``[`` ends in ``RecursionError``; a 2 000-digit integer parses
to an int no float can hold. The text is scanned first (outside strings and
comments) for bracket nesting and the length of number literals, and the
parsed data is walked (without recursion) for the depth that dotted keys can
build. Every problem is a :class:`~workbench.errors.DesignError`.
"""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

from .errors import DesignError

__all__ = ["MAX_BYTES", "MAX_DEPTH", "MAX_DIGITS", "load_toml", "scan_limits"]

#: largest design file read (bytes)
MAX_BYTES = 1_000_000
#: deepest nesting of tables and arrays (a design needs about 5)
MAX_DEPTH = 32
#: most digits in one number literal (a float has 17 significant digits)
MAX_DIGITS = 40

_NUMBER = re.compile(r"[0-9_]+")


def scan_limits(text: str) -> tuple[str, str] | None:
    """The first limit the raw text breaks, as (what, found), or None.

    Scans outside strings and comments: bracket depth (``[`` and ``{``) and
    the length of each run of digits.
    """
    depth, i, n = 0, 0, len(text)
    while i < n:
        c = text[i]
        if c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j + 1
            continue
        if c in "\"'":
            triple = text.startswith(c * 3, i)
            quote = c * 3 if triple else c
            j = i + len(quote)
            while j < n and not text.startswith(quote, j):
                if c == '"' and text[j] == "\\":
                    j += 1
                elif not triple and text[j] == "\n":
                    break
                j += 1
            i = j + len(quote)
            continue
        if c in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                return f"at most {MAX_DEPTH} nested tables or arrays", f"<deeper than {MAX_DEPTH}>"
        elif c in "]}":
            depth = max(depth - 1, 0)
        elif c.isdigit():
            m = _NUMBER.match(text, i)
            digits = len(m.group().replace("_", ""))
            if digits > MAX_DIGITS:
                return (f"number literals of at most {MAX_DIGITS} digits",
                        f"<a number of {digits} digits>")
            i = m.end()
            continue
        i += 1
    return None


def _depth(data: dict) -> int:
    """Nesting depth of parsed TOML data (iterative: no recursion limit)."""
    deepest, stack = 0, [(data, 1)]
    while stack:
        obj, d = stack.pop()
        deepest = max(deepest, d)
        if d > MAX_DEPTH:
            break
        kids = obj.values() if isinstance(obj, dict) else obj
        stack += [(k, d + 1) for k in kids if isinstance(k, (dict, list))]
    return deepest


def load_toml(path: str | Path, shown: str) -> dict:
    """Parse the TOML file ``path`` within the limits above.

    Parameters
    ----------
    path : path
        The file.
    shown : str
        The file as named in messages.

    Raises
    ------
    DesignError
        Unreadable, too large, too deeply nested, a too long number, or not TOML.
    """
    try:
        raw = Path(path).read_bytes()
    except OSError as exc:
        raise DesignError(shown, "<file>", "<unreadable>", f"a readable file ({exc.strerror})"
                          ) from None
    if len(raw) > MAX_BYTES:
        raise DesignError(shown, "<file>", f"<{len(raw)} bytes>", f"at most {MAX_BYTES} bytes")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DesignError(shown, "<file>", "<unparsable>", f"UTF-8 text ({exc.reason} at "
                          f"byte {exc.start})") from None
    broken = scan_limits(text)
    if broken:
        raise DesignError(shown, "<file>", broken[1], broken[0])
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DesignError(shown, "<file>", "<unparsable>", f"valid TOML ({exc})") from None
    except (RecursionError, ValueError) as exc:   # ValueError: int > sys int digit limit
        raise DesignError(shown, "<file>", "<unparsable>",
                          f"TOML within the limits ({type(exc).__name__})") from None
    if _depth(data) > MAX_DEPTH:
        raise DesignError(shown, "<file>", f"<deeper than {MAX_DEPTH}>",
                          f"at most {MAX_DEPTH} nested tables or arrays (dotted keys count)")
    return data
