"""The on-disk Numba cache is dropped when any compiled source changes."""

from __future__ import annotations

from shakermill.support import numba_cache as _numba_cache


def test_stale_cache_is_dropped_and_a_current_one_kept(tmp_path) -> None:
    stale = tmp_path / "integrate._advance-1.py311.nbi"
    stale.write_text("old machine code index")
    assert _numba_cache.drop_stale_cache(tmp_path, (tmp_path,)) is True
    assert not stale.exists()
    assert (tmp_path / "numba-sources.sha256").read_text() == _numba_cache.sources_digest()
    current = tmp_path / "integrate._advance-1.py311.nbc"
    current.write_text("machine code compiled from the current sources")
    assert _numba_cache.drop_stale_cache(tmp_path, (tmp_path,)) is False
    assert current.exists()


def test_every_compiled_source_is_in_the_stamp() -> None:
    # A compiled function inlined or called from another module's cached code must change the stamp when it
    # changes: every module that compiles with Numba is listed.
    package = _numba_cache._PACKAGE
    compiled = {path for path in package.rglob("*.py") if "@njit(" in path.read_text(encoding="utf-8")}
    assert set(_numba_cache._COMPILED_SOURCES) == compiled
