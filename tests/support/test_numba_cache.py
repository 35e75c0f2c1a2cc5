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
