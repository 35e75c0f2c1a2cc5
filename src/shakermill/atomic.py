"""Atomic file writing: readers never see half a file, an interruption leaves the old one or none."""

from __future__ import annotations

import os
import secrets
from pathlib import Path


class StorageError(Exception):
    """A run folder cannot be written to, or read from, the given path (raised by :mod:`shakermill.storage`)."""


def partial_path(path: Path) -> Path:
    """A hidden, unique sibling of ``path`` to write into before the rename."""
    return path.with_name(f".{path.name}.partial-{secrets.token_hex(4)}")


def write_text_atomically(path: Path | str, text: str) -> Path:
    """Write ``text`` through a temporary sibling and a rename; return ``path``."""
    path = Path(path)
    partial = partial_path(path)
    try:
        partial.write_text(text, encoding="utf-8")
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)
    return path
