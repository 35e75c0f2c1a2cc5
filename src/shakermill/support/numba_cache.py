"""Keep Numba's on-disk cache consistent across modules.

Numba invalidates a cached function only when the file that defines it changes,
not when a function it calls from another module does: after an edit of
``engines/one_d/model.py`` the cached integrator loop would still run the old
right-hand side, silently. So the cache is keyed here on all compiled sources
together, and a change of any of them drops the cached code of all.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_PACKAGE = Path(__file__).parent.parent
_COMPILED_SOURCES = tuple(
    _PACKAGE / name
    for name in (
        "physics/kinematics.py",
        "physics/contact.py",
        "physics/thermal.py",
        "physics/heat_paths.py",
        "engines/thermal/kernel.py",
        "engines/one_d/model.py",
        "engines/one_d/contacts.py",
        "engines/one_d/integrator.py",
        "engines/dem/vectors.py",
        "engines/dem/neighbours.py",
        "engines/dem/contacts.py",
        "engines/dem/stepper.py",
    )
)
# Numba keeps each module's cached code in the __pycache__ beside it.
_CACHE_FOLDERS = tuple(sorted({source.parent / "__pycache__" for source in _COMPILED_SOURCES}))
_STAMP_NAME = "numba-sources.sha256"


def sources_digest() -> str:
    return hashlib.sha256(b"".join(source.read_bytes() for source in _COMPILED_SOURCES)).hexdigest()


def drop_stale_cache(
    stamp_folder: Path = _PACKAGE / "__pycache__", cache_folders: tuple[Path, ...] = _CACHE_FOLDERS
) -> bool:
    """Delete cached machine code compiled from other sources; return True when something was dropped."""
    digest = sources_digest()
    stamp = stamp_folder / _STAMP_NAME
    try:
        if stamp.read_text() == digest:
            return False
    except OSError:
        pass
    try:
        for folder in cache_folders:
            for cached in [*folder.glob("*.nbi"), *folder.glob("*.nbc")]:
                cached.unlink(missing_ok=True)
        stamp_folder.mkdir(exist_ok=True)
        stamp.write_text(digest)
    except OSError:
        # A read-only installation: Numba then keeps its cache elsewhere and checks nothing more.
        return False
    return True
