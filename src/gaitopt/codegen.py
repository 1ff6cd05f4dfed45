"""Generating C code from CasADi Functions, compiling it, and caching the result on disk.

The cache is content-addressed: the key is a hash of the generated C source and the compiler
command, so a changed model, problem or compiler flag gives a new library and an unchanged one
is loaded from disk without compiling. The cache folder is ``$GAITOPT_CACHE`` if set, else
``$XDG_CACHE_HOME/gaitopt`` (``~/.cache/gaitopt``).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path

import casadi as ca

DEFAULT_FLAGS: tuple[str, ...] = ("-O2", "-fPIC", "-shared")


class CompileError(RuntimeError):
    """The C compiler failed or is missing."""


def cache_dir() -> Path:
    """The folder holding compiled libraries (created on demand)."""
    root = os.environ.get("GAITOPT_CACHE")
    if root:
        path = Path(root)
    else:
        base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        path = Path(base) / "gaitopt"
    path.mkdir(parents=True, exist_ok=True)
    return path


def compiler() -> str:
    """The C compiler to use: ``$CC`` or ``gcc`` or ``cc``."""
    for candidate in (os.environ.get("CC"), "gcc", "cc"):
        if candidate and shutil.which(candidate):
            return candidate
    raise CompileError("no C compiler found (set CC, or install gcc)")


def generate_source(functions: Sequence[ca.Function], name: str) -> str:
    """C source defining every function in ``functions`` (CasADi's generated code)."""
    gen = ca.CodeGenerator(f"{name}.c", {"with_header": False, "casadi_real": "double"})
    for f in functions:
        gen.add(f)
    return str(gen.dump())


def compile_library(source: str, name: str, *, flags: Sequence[str] = DEFAULT_FLAGS) -> Path:
    """Compile C ``source`` to a shared library in the cache and return its path.

    A library with the same source and flags already in the cache is reused as it is.
    """
    cc = compiler()
    key = hashlib.sha256("\0".join([source, cc, *flags]).encode()).hexdigest()[:20]
    target = cache_dir() / f"{name}-{key}.so"
    if target.exists():
        return target
    with tempfile.TemporaryDirectory(prefix="gaitopt-cc-") as tmp:
        c_file = Path(tmp) / f"{name}.c"
        c_file.write_text(source)
        so_tmp = Path(tmp) / f"{name}.so"
        cmd = [cc, *flags, str(c_file), "-o", str(so_tmp), "-lm"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise CompileError(f"{' '.join(cmd)} failed:\n{proc.stderr[-2000:]}")
        # Atomic publish: concurrent processes may compile the same key.
        fd, staged = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
        os.close(fd)
        shutil.copyfile(so_tmp, staged)
        os.replace(staged, target)
    return target


def compile_functions(functions: Sequence[ca.Function], name: str, *,
                      flags: Sequence[str] = DEFAULT_FLAGS) -> dict[str, ca.Function]:
    """Compile CasADi Functions to C (cached) and load them back as external Functions.

    Returns the loaded functions by name. External functions evaluate numerically and
    symbolically (as calls), with the same inputs and outputs as the originals.
    """
    path = compile_library(generate_source(functions, name), name, flags=flags)
    return {f.name(): ca.external(f.name(), str(path)) for f in functions}
