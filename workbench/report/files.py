"""Writing report files: whole or not at all."""
from __future__ import annotations

from pathlib import Path


def atomic_write(path: Path, data: str | bytes) -> Path:
    """Write text (UTF-8) or bytes to ``path`` through a temporary file, so a
    reader never sees it half-written; returns ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    if isinstance(data, bytes):
        tmp.write_bytes(data)
    else:
        tmp.write_text(data, encoding="utf-8")
    tmp.replace(path)
    return path
