"""The disk cache of symbolic CasADi functions: a file per function, keyed by what built it
(the model, the options that shape it, the gaitopt sources, CasADi's version), pickled
atomically and pruned to its size (:mod:`gaitopt.codegen`). Used by the multibody functions
(:mod:`gaitopt.dynamics.functions`: contact dynamics, impact and liftoff maps, which
``verify``, the stability analysis and the records build in every process), the walking
problem's transcriptions (:mod:`gaitopt.gait.solve.transcriptions`) and both formulations'
records."""

from __future__ import annotations

import contextlib
import functools
import hashlib
import pickle
from collections.abc import Callable
from pathlib import Path
from typing import Any

import casadi as ca

from gaitopt import codegen
from gaitopt.fileio import write_bytes_atomic


@functools.cache
def source_hash() -> str:
    """A hash of every Python file of the installed gaitopt package: the symbolic functions
    cached on disk are those this code builds."""
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:20]


def cached_functions(path: Path) -> Any:
    """The functions pickled at ``path``, or None (missing, unreadable or stale: rebuilt)."""
    try:
        functions = pickle.loads(path.read_bytes())
    except Exception:  # noqa: BLE001 - any unreadable cache file is rebuilt and replaced
        return None
    codegen.mark_used(path)
    return functions


def save_functions(path: Path, functions: Any) -> None:
    """Pickle ``functions`` to the cache file ``path`` atomically, then bound the cache's
    size (:func:`gaitopt.codegen.prune_cache`); a read-only or full disk only costs the
    build next time."""
    with contextlib.suppress(OSError):
        write_bytes_atomic(path, pickle.dumps(functions))
        codegen.prune_cache()


def function_file(kind: str, key: tuple[Any, ...]) -> Path:
    """Where a symbolic function of ``kind`` (a file-name prefix) built from ``key`` is cached
    on disk: keyed by ``kind``, ``key`` (its repr: model hashes, names), the gaitopt sources
    and CasADi's version, as the walking problem's functions
    (:func:`gaitopt.gait.solve.transcriptions.functions_file`)."""
    text = repr((kind, source_hash(), ca.CasadiMeta.version(), key))
    name = hashlib.sha256(text.encode()).hexdigest()[:24]
    return codegen.cache_dir() / f"{kind}-{name}.pickle"


def disk_cached(path: Path, build: Callable[[], ca.Function]) -> ca.Function:
    """The CasADi function pickled at ``path`` (:func:`function_file`), or ``build()``
    saved there atomically (a read-only or full cache only costs the build next time)."""
    cached = cached_functions(path)
    if isinstance(cached, ca.Function):
        return cached
    fn = build()
    save_functions(path, fn)
    return fn
