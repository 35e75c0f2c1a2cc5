"""Keep Numba's on-disk cache consistent across modules.

Numba invalidates a cached function only when the file that defines it changes,
not when a function it calls from another module does: after an edit of
``model.py`` the cached integrator loop would still run the old right-hand side,
silently. So the cache is keyed here on all compiled sources together.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_PACKAGE = Path(__file__).parent
_COMPILED_SOURCES = ("drive.py", "contact.py", "thermal.py", "model.py", "integrate.py")
_STAMP_NAME = "numba-sources.sha256"


def sources_digest() -> str:
    return hashlib.sha256(b"".join((_PACKAGE / name).read_bytes() for name in _COMPILED_SOURCES)).hexdigest()


def drop_stale_cache(cache_dir: Path = _PACKAGE / "__pycache__") -> bool:
    """Delete cached machine code compiled from other sources; return True when something was dropped."""
    digest = sources_digest()
    stamp = cache_dir / _STAMP_NAME
    try:
        if stamp.read_text() == digest:
            return False
    except OSError:
        pass
    try:
        for cached in [*cache_dir.glob("*.nbi"), *cache_dir.glob("*.nbc")]:
            cached.unlink(missing_ok=True)
        cache_dir.mkdir(exist_ok=True)
        stamp.write_text(digest)
    except OSError:
        # A read-only installation: Numba then keeps its cache elsewhere and checks nothing more.
        return False
    return True
