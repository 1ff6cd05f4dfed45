"""Generating C code from CasADi Functions, compiling it, and caching the result on disk.

The cache is content-addressed: the key is a hash of the generated C source and the compiler
command, so a changed model, problem or compiler flag gives a new library and an unchanged one
is loaded from disk without compiling. The cache folder is ``$GAITOPT_CACHE`` if set, else
``$XDG_CACHE_HOME/gaitopt`` (``~/.cache/gaitopt``).

The folder also holds the pickled symbolic functions of :mod:`gaitopt.gait.solve.transcriptions`,
keyed by the gaitopt sources among others, so every new version (or edit) of gaitopt adds
files and never reuses the old ones. :func:`prune_cache` bounds the folder's size: whenever a
file is added and the folder holds more than ``$GAITOPT_CACHE_MAX_MB`` megabytes
(:data:`CACHE_LIMIT_MB` by default), the least recently used files are deleted until it holds
at most 80 % of that; a file counts as used when it is written or loaded (:func:`mark_used`
sets its modification time).
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import re
import shutil
import subprocess
import tempfile
import time
import warnings
from collections.abc import Sequence
from pathlib import Path

import casadi as ca

DEFAULT_FLAGS: tuple[str, ...] = ("-O2", "-fPIC", "-shared")
#: Size limit of the disk cache (MB) when ``$GAITOPT_CACHE_MAX_MB`` is not set: one model and
#: problem's libraries and functions take a few MB to a few tens of MB.
CACHE_LIMIT_MB = 500.0
#: :func:`prune_cache` deletes down to this share of the limit, so it does not run after
#: every write once the folder is full.
PRUNE_TO = 0.8
#: :func:`prune_cache` never deletes a file used (written or loaded) this recently (s): a
#: process may have found a library and not loaded it yet.
KEEP_RECENT_S = 120.0


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


def cache_limit_bytes() -> int:
    """The disk cache's size limit in bytes: ``$GAITOPT_CACHE_MAX_MB`` megabytes, or
    :data:`CACHE_LIMIT_MB`. A value that is not a number > 0 is ignored with a warning
    that names the variable (a solve never fails for its cache)."""
    text = os.environ.get("GAITOPT_CACHE_MAX_MB", "").strip()
    if not text:
        return int(CACHE_LIMIT_MB * 1e6)
    try:
        mb = float(text)
    except ValueError:
        mb = math.nan
    if not (math.isfinite(mb) and mb > 0):
        warnings.warn(f"GAITOPT_CACHE_MAX_MB = {text!r}: must be a number of megabytes > 0; "
                      f"using {CACHE_LIMIT_MB:g}", RuntimeWarning, stacklevel=2)
        return int(CACHE_LIMIT_MB * 1e6)
    return int(mb * 1e6)


def mark_used(path: Path) -> None:
    """Record that the cache file ``path`` was just used (its modification time), so
    :func:`prune_cache` keeps it over older ones. A file that vanished is ignored."""
    with contextlib.suppress(OSError):
        os.utime(path)


def prune_cache(limit: int | None = None) -> list[Path]:
    """Delete the least recently used files of :func:`cache_dir` (oldest modification time
    first) while it holds more than ``limit`` bytes (:func:`cache_limit_bytes`), down to
    :data:`PRUNE_TO` of it, sparing files used in the last :data:`KEEP_RECENT_S` seconds;
    return the deleted paths. Hidden files (another process's files
    being written) are neither counted nor deleted; a file another process deleted first is
    skipped. A library this process has loaded stays usable (Linux keeps a deleted file's
    mapping); it is compiled again only by a later process that needs it."""
    limit = cache_limit_bytes() if limit is None else limit
    recent = time.time() - KEEP_RECENT_S
    entries: list[tuple[float, int, Path]] = []
    for path in cache_dir().iterdir():
        if path.name.startswith("."):
            continue
        with contextlib.suppress(OSError):
            st = path.stat()
            if path.is_file():
                entries.append((st.st_mtime, st.st_size, path))
    total = sum(size for _, size, _ in entries)
    if total <= limit:
        return []
    removed = []
    for mtime, size, path in sorted(entries, key=lambda e: e[0]):
        if total <= PRUNE_TO * limit or mtime > recent:
            break
        with contextlib.suppress(OSError):
            path.unlink()
            total -= size
            removed.append(path)
    return removed


def compiler() -> str:
    """The C compiler to use: ``$CC`` or ``gcc`` or ``cc``."""
    for candidate in (os.environ.get("CC"), "gcc", "cc"):
        if candidate and shutil.which(candidate):
            return candidate
    raise CompileError("no C compiler found (set CC, or install gcc)")


def has_compiler() -> bool:
    """Whether a C compiler is available (see :func:`compiler`)."""
    try:
        compiler()
    except CompileError:
        return False
    return True


def generate_source(functions: Sequence[ca.Function], name: str) -> str:
    """C source defining every function in ``functions`` (CasADi's generated code)."""
    gen = ca.CodeGenerator(f"{name}.c", {"with_header": False, "casadi_real": "double"})
    for f in functions:
        gen.add(f)
    return str(gen.dump())


#: Statements per chunk of :func:`split_straight_line`: the seven-link biped's point library
#: of the heel-off phase (Jacobian and Hessian, 46,000 statements) compiles at ``-Og`` in
#: 2.5 s in chunks of 100 (``-O0`` whole: 1.3 s, ``-O1`` whole: 8.8 s) and evaluates the
#: Hessian of one point in 12.7 us (``-O0``: 36 us, ``-O1`` whole: 11.6 us); chunks of 25,
#: 300, 1000 and 3000: 3.1, 3.0, 3.7 and 4.8 s, 13-15 us.
CHUNK_STATEMENTS = 100

_FUNCTION = re.compile(r"static int (casadi_f\d+)\(const casadi_real\*\* arg, "
                       r"casadi_real\*\* res, casadi_int\* iw, casadi_real\* w, int mem\) \{")
_DECLARATION = re.compile(r"  casadi_real a\d+(?:, a\d+)*;")
_ASSIGNMENT = re.compile(r"  (a\d+)=([^;]*);")
_OUTPUT = re.compile(r"  if \(res\[\d+\]!=0\) res\[\d+\]\[\d+\]=([^;]*);")
_LOCAL = re.compile(r"\ba\d+\b")
#: What a statement of straight-line code never refers to (a call, the work vectors).
_NOT_STRAIGHT = re.compile(r"\b(?:w|iw|mem|casadi_f\d+)\b")
_NOINLINE = """#if defined(__GNUC__)
#define GAITOPT_NOINLINE __attribute__((noinline))
#else
#define GAITOPT_NOINLINE
#endif"""


def split_straight_line(source: str, statements: int = CHUNK_STATEMENTS) -> str:
    """CasADi's generated C ``source`` with every straight-line function of more than
    ``statements`` statements split into chunk functions of at most ``statements`` each,
    called in order; the same arithmetic in the same order, so the results are bitwise the
    same.

    An SX function's C is one function of local variables ``aNNN`` (reused: CasADi allocates
    them like registers) assigned one operation at a time, and of guarded writes of the
    outputs (``if (res[i]!=0) res[i][k]=aNNN;``). A C compiler's register allocation over one
    such function of tens of thousands of statements takes most of an optimizing compile (GCC
    12 at ``-O1``: 6.6 of 8.8 s for the seven-link heel-off library). Each chunk here
    declares its own locals, loads those it reads before it assigns them from an array
    ``s`` of the caller's stack (one entry per such variable), and stores those a later
    chunk reads before assigning them; chunks are not inlined (``GAITOPT_NOINLINE``).
    A function with any other statement (a call, the work vectors ``w``, ``iw``) is left
    as it is.
    """
    if statements < 1:
        raise ValueError(f"statements: {statements}; allowed: an integer >= 1")
    lines = source.split("\n")
    out: list[str] = []
    i, split_any = 0, False
    while i < len(lines):
        head = _FUNCTION.fullmatch(lines[i])
        end = _closing(lines, i) if head else -1
        head = head if end > i else None
        body = lines[i + 1:end] if head else []
        stmts = [line for line in body if not _DECLARATION.fullmatch(line)]
        if (head is None or len(stmts) <= statements + 1 or stmts[-1] != "  return 0;"
                or not all(_straight(line) for line in stmts[:-1])):
            out.extend(lines[i:end + 1] if head else lines[i:i + 1])
            i = end + 1 if head else i + 1
            continue
        out.extend(_chunked(head.group(1), stmts[:-1], statements))
        split_any = True
        i = end + 1
    if split_any:
        first = next(k for k, line in enumerate(out) if _FUNCTION.fullmatch(line)
                     or line.startswith("static GAITOPT_NOINLINE"))
        out[first:first] = [_NOINLINE, ""]
    return "\n".join(out)


def _closing(lines: list[str], start: int) -> int:
    """The index of the first line ``}`` after ``start`` (a function's end), or -1."""
    try:
        return lines.index("}", start)
    except ValueError:
        return -1


def _straight(line: str) -> bool:
    """Whether ``line`` is an assignment of a local or a guarded output write referring to
    nothing but locals, the inputs and constants."""
    m = _ASSIGNMENT.fullmatch(line) or _OUTPUT.fullmatch(line)
    return m is not None and not _NOT_STRAIGHT.search(m.groups()[-1])


def _chunked(name: str, stmts: list[str], statements: int) -> list[str]:
    """The chunk functions of function ``name`` and the function calling them (see
    :func:`split_straight_line`)."""
    chunks = [stmts[k:k + statements] for k in range(0, len(stmts), statements)]
    reads: list[set[str]] = []
    writes: list[set[str]] = []
    for chunk in chunks:
        read: set[str] = set()
        written: set[str] = set()
        for line in chunk:
            m = _ASSIGNMENT.fullmatch(line)
            rhs = m.group(2) if m else line
            read.update(n for n in _LOCAL.findall(rhs) if n not in written)
            if m:
                written.add(m.group(1))
        reads.append(read)
        writes.append(written)
    # live[k]: the locals a chunk after k reads before any chunk after k assigns them.
    live: list[set[str]] = [set() for _ in chunks]
    later: set[str] = set()
    for k in range(len(chunks) - 1, -1, -1):
        live[k] = set(later)
        later = reads[k] | (later - writes[k])
    slot: dict[str, int] = {}
    for k in range(len(chunks)):
        for n in sorted(reads[k] | (writes[k] & live[k])):
            slot.setdefault(n, len(slot))
    out: list[str] = []
    for k, chunk in enumerate(chunks):
        out.append(f"static GAITOPT_NOINLINE void {name}_chunk{k}(const casadi_real** arg, "
                   "casadi_real** res, casadi_real* s) {")
        local = sorted(reads[k] | writes[k])
        out += ["  casadi_real " + ", ".join(local[p:p + 12]) + ";"
                for p in range(0, len(local), 12)]
        out += [f"  {n}=s[{slot[n]}];" for n in sorted(reads[k])]
        out += chunk
        out += [f"  s[{slot[n]}]={n};" for n in sorted(writes[k] & live[k])]
        out += ["}", ""]
    out.append(f"static int {name}(const casadi_real** arg, casadi_real** res, "
               "casadi_int* iw, casadi_real* w, int mem) {")
    out.append(f"  casadi_real s[{max(len(slot), 1)}];")
    out += [f"  {name}_chunk{k}(arg, res, s);" for k in range(len(chunks))]
    out += ["  return 0;", "}"]
    return out


def library_path(source: str, name: str, flags: Sequence[str] = DEFAULT_FLAGS) -> Path:
    """Where the library of C ``source`` compiled with ``flags`` is (or will be) cached:
    ``<cache>/<name>-<hash of source, compiler and flags>.so``."""
    key = hashlib.sha256("\0".join([source, compiler(), *flags]).encode()).hexdigest()[:20]
    return cache_dir() / f"{name}-{key}.so"


def compile_library(source: str, name: str, *, flags: Sequence[str] = DEFAULT_FLAGS) -> Path:
    """Compile C ``source`` to a shared library in the cache and return its path.

    A library with the same source and flags already in the cache is reused as it is.
    """
    return compile_libraries({name: source}, flags=flags)[name]


def compile_libraries(sources: dict[str, str], *, flags: Sequence[str] = DEFAULT_FLAGS,
                      targets: dict[str, Path] | None = None,
                      flags_by_name: dict[str, Sequence[str]] | None = None
                      ) -> dict[str, Path]:
    """Compile several C sources (by library name) to shared libraries in the cache, the
    compilers running in parallel, and return their paths by name. Libraries already in the
    cache (same source, compiler and flags) are reused as they are. ``targets`` gives the
    paths instead (a caller that keys the cache by what generates the source);
    ``flags_by_name`` other flags for some libraries."""
    cc = compiler()
    flags_of = {name: tuple((flags_by_name or {}).get(name, flags)) for name in sources}
    if targets is None:
        targets = {name: library_path(src, name, flags_of[name])
                   for name, src in sources.items()}
    todo = [name for name, path in targets.items() if not path.exists()]
    for name, path in targets.items():
        if name not in todo:
            mark_used(path)
    if not todo:
        return targets
    with tempfile.TemporaryDirectory(prefix="gaitopt-cc-") as tmp:
        running = []
        for name in todo:
            c_file = Path(tmp) / f"{name}.c"
            c_file.write_text(sources[name])
            so_tmp = Path(tmp) / f"{name}.so"
            cmd = [cc, *flags_of[name], str(c_file), "-o", str(so_tmp), "-lm"]
            running.append((name, cmd, so_tmp,
                            subprocess.Popen(cmd, stdout=subprocess.PIPE,
                                             stderr=subprocess.PIPE, text=True)))
        failed = []
        for name, cmd, so_tmp, proc in running:
            _, err = proc.communicate()
            if proc.returncode != 0:
                failed.append(f"{' '.join(cmd)} failed:\n{err[-2000:]}")
                continue
            # Atomic publish: concurrent processes may compile the same key.
            target = targets[name]
            fd, staged = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
            os.close(fd)
            shutil.copyfile(so_tmp, staged)
            os.replace(staged, target)
        if failed:
            raise CompileError("\n".join(failed))
    prune_cache()
    return targets


def compile_functions(functions: Sequence[ca.Function], name: str, *,
                      flags: Sequence[str] = DEFAULT_FLAGS) -> dict[str, ca.Function]:
    """Compile CasADi Functions to C (cached) and load them back as external Functions.

    Returns the loaded functions by name. External functions evaluate numerically and
    symbolically (as calls), with the same inputs and outputs as the originals.
    """
    path = compile_library(generate_source(functions, name), name, flags=flags)
    return {f.name(): ca.external(f.name(), str(path)) for f in functions}
