"""The disk cache stays within its size limit: writing a file into a full cache deletes the
least recently used files (oldest modification time; loading a file counts as using it)
down to 80 % of ``$GAITOPT_CACHE_MAX_MB``; an invalid limit is ignored with a warning that
names the variable."""

from __future__ import annotations

import os
from pathlib import Path

import casadi as ca
import pytest

from gaitopt import codegen
from gaitopt.gait.solve import transcriptions


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    monkeypatch.setenv("GAITOPT_CACHE_MAX_MB", "0.01")  # 10,000 bytes
    return tmp_path


def _file(folder: Path, name: str, size: int, age_s: float) -> Path:
    """A cache file of ``size`` bytes last used ``age_s`` seconds ago (plus the minutes
    :func:`gaitopt.codegen.prune_cache` spares)."""
    path = folder / name
    path.write_bytes(b"x" * size)
    t = path.stat().st_mtime - codegen.KEEP_RECENT_S - age_s
    os.utime(path, (t, t))
    return path


def test_the_least_recently_used_files_go_first(cache: Path) -> None:
    old = [_file(cache, f"old-{i}.pickle", 1000, 100.0 - i) for i in range(2)]
    new = _file(cache, "new.so", 1000, 1.0)
    recent = cache / "recent.so"  # used a moment ago: spared even when the cache is full
    recent.write_bytes(b"x" * 9000)
    hidden = _file(cache, ".new.so.tmp", 5000, 500.0)  # another process's file being written
    assert sum(p.stat().st_size for p in (*old, new, recent)) == 12_000
    removed = codegen.prune_cache()
    # 12,000 bytes > 10,000: the oldest go first, toward at most 8,000 bytes, but not the
    # file used a moment ago (the folder stays at 9,000 until that file ages).
    assert removed == [*old, new]
    assert [p.exists() for p in (*old, new, recent, hidden)] == [False] * 3 + [True] * 2
    assert codegen.prune_cache() == []  # within the limit now


def test_a_loaded_file_counts_as_used(cache: Path) -> None:
    fn = ca.Function("f", [ca.SX.sym("x")], [ca.SX.sym("x") * 0])
    kept = cache / "kept.pickle"
    transcriptions.save_functions(kept, fn)
    os.utime(kept, (1.0, 1.0))  # written long ago ...
    others = [_file(cache, f"other-{i}.pickle", 3500, 50.0 - i) for i in range(3)]
    assert isinstance(transcriptions.cached_functions(kept), ca.Function)  # ... used now
    transcriptions.save_functions(cache / "more.pickle", fn)  # a write prunes
    assert kept.exists() and (cache / "more.pickle").exists()
    assert [p.exists() for p in others] == [False, False, True]


def test_an_invalid_limit_is_ignored_with_a_warning(cache: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    for text in ("lots", "-5", "0", "nan"):
        monkeypatch.setenv("GAITOPT_CACHE_MAX_MB", text)
        with pytest.warns(RuntimeWarning, match="GAITOPT_CACHE_MAX_MB"):
            assert codegen.cache_limit_bytes() == int(codegen.CACHE_LIMIT_MB * 1e6)
    monkeypatch.setenv("GAITOPT_CACHE_MAX_MB", "2.5")
    assert codegen.cache_limit_bytes() == 2_500_000
