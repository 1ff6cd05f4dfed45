"""One code path for floats and CasADi symbols.

Every dynamics algorithm is written on *scalars*: Python floats, or 1x1 CasADi ``SX``/``MX``
expressions. ``casadi.sin`` and friends return floats on floats, and ``+ - * /`` work on any
mix, so the same scalar code evaluates numbers or builds expression graphs. This module holds
the few places where the two worlds differ:

* :func:`as_scalars` turns an input vector (NumPy array, list, ``DM``, ``SX``/``MX`` column)
  into a list of scalars, checking its length;
* :func:`vector` and :func:`matrix` turn lists of scalars back into an ``np.ndarray`` when
  every entry is a number, or into a CasADi ``SX``/``MX`` otherwise;
* :func:`ldl_factor` and :func:`ldl_solve` (and :func:`spd_inverse`) solve small symmetric
  positive-definite systems by an ``L D L^T`` factorization written in scalars (no square
  roots, no pivoting), so they too work on both.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import casadi as ca
import numpy as np

#: A float or a 1x1 CasADi SX/MX expression.
Scalar = Any
#: A list of scalars (the internal form of every vector).
Scalars = list[Any]


def is_symbolic(x: Any) -> bool:
    """True for CasADi ``SX``/``MX`` expressions (``DM`` counts as numeric)."""
    return isinstance(x, ca.SX | ca.MX)


def sin(x: Scalar) -> Scalar:
    return math.sin(x) if isinstance(x, float | int) else ca.sin(x)


def cos(x: Scalar) -> Scalar:
    return math.cos(x) if isinstance(x, float | int) else ca.cos(x)


def sqrt(x: Scalar) -> Scalar:
    return math.sqrt(x) if isinstance(x, float | int) else ca.sqrt(x)


def atan2(y: Scalar, x: Scalar) -> Scalar:
    if isinstance(y, float | int) and isinstance(x, float | int):
        return math.atan2(y, x)
    return ca.atan2(y, x)


def as_scalars(x: Any, n: int, name: str, names: Sequence[str] | None = None) -> Scalars:
    """The ``n`` entries of the vector ``x`` as scalars.

    ``x`` may be a NumPy array or list of shape ``(n,)`` (or ``(n, 1)``/``(1, n)``), a CasADi
    ``DM``, an ``SX``/``MX`` column or row of ``n`` entries, or a list mixing numbers and 1x1
    symbols. Numbers become Python floats and must be finite. ``names`` (the meaning of each
    entry) is quoted in the error message.
    """
    expected = f"{n} entries" + (f" ({', '.join(names)})" if names else "")
    if isinstance(x, ca.SX | ca.MX):
        if x.numel() != n or (n > 1 and min(x.size1(), x.size2()) > 1):
            raise ValueError(f"{name} must be a vector of {expected}, got a {x.size1()}x"
                             f"{x.size2()} CasADi {type(x).__name__}")
        return [x[i] for i in range(n)]
    if isinstance(x, ca.DM):
        x = x.full()
    if isinstance(x, list | tuple) and any(is_symbolic(e) for e in x):
        if len(x) != n:
            raise ValueError(f"{name} must have {expected}, got {len(x)}")
        out: Scalars = []
        for i, e in enumerate(x):
            if is_symbolic(e):
                if e.numel() != 1:
                    raise ValueError(f"{name}[{i}] must be a scalar, got shape {e.shape}")
                out.append(e)
            else:
                out.append(_finite(e, f"{name}[{i}]"))
        return out
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a numeric vector of {expected}, got {x!r}") from None
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.reshape(-1)
    if arr.shape != (n,):
        raise ValueError(f"{name} must have {expected}, got an array of shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = int(np.flatnonzero(~np.isfinite(arr))[0])
        raise ValueError(f"{name}[{bad}] = {arr[bad]} is not finite")
    return [float(v) for v in arr]


def _finite(value: Any, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} = {v} is not finite")
    return v


def as_scalar(x: Any, name: str) -> Scalar:
    """A single number (finite float) or a 1x1 symbol."""
    if is_symbolic(x):
        if x.numel() != 1:
            raise ValueError(f"{name} must be a scalar, got shape {x.shape}")
        return x
    if isinstance(x, ca.DM | np.ndarray):
        if np.size(x) != 1:
            raise ValueError(f"{name} must be a scalar, got shape {np.shape(x)}")
        x = np.asarray(x, dtype=float).reshape(-1)[0]
    return _finite(x, name)


def vector(entries: Sequence[Scalar]) -> Any:
    """An ``np.ndarray`` of shape ``(n,)`` if all entries are numbers, else a CasADi column."""
    if any(is_symbolic(e) for e in entries):
        return ca.vertcat(*entries)
    return np.array([float(e) for e in entries], dtype=float)


def matrix(rows: Sequence[Sequence[Scalar]], ncols: int | None = None) -> Any:
    """An ``np.ndarray`` ``(m, n)`` if all entries are numbers, else a CasADi matrix."""
    if not rows:
        return np.zeros((0, ncols or 0))
    if any(is_symbolic(e) for row in rows for e in row):
        return ca.vertcat(*[ca.horzcat(*row) for row in rows])
    return np.array([[float(e) for e in row] for row in rows], dtype=float).reshape(
        len(rows), len(rows[0]) if ncols is None else ncols)


def dot(a: Sequence[Scalar], b: Sequence[Scalar]) -> Scalar:
    """``sum_i a_i b_i`` (0.0 for empty vectors)."""
    total: Scalar = 0.0
    for x, y in zip(a, b, strict=True):
        total = total + x * y
    return total


def matvec(a: Sequence[Sequence[Scalar]], x: Sequence[Scalar]) -> Scalars:
    """``A x`` for ``A`` given as a list of rows."""
    return [dot(row, x) for row in a]


class SingularSystemError(ValueError):
    """A linear system that should be positive definite is singular (numerically)."""


def ldl_factor(a: Sequence[Sequence[Scalar]], what: str = "matrix") -> tuple[list[Scalars],
                                                                             Scalars]:
    """``A = L D L^T`` for a symmetric positive-definite ``A`` (n x n, list of rows).

    Returns the unit lower-triangular ``L`` (list of rows) and the diagonal ``D``. Numeric
    pivots that are not clearly positive raise :class:`SingularSystemError` naming ``what``.
    """
    n = len(a)
    lower: list[Scalars] = [[0.0] * n for _ in range(n)]
    diag: Scalars = [0.0] * n
    scale = max((abs(a[i][i]) for i in range(n) if not is_symbolic(a[i][i])), default=0.0)
    for j in range(n):
        d = a[j][j]
        for k in range(j):
            d = d - lower[j][k] * lower[j][k] * diag[k]
        if not is_symbolic(d) and not d > 1e-12 * scale:
            raise SingularSystemError(
                f"{what} is singular or not positive definite (pivot {j} = {float(d):.3g}); "
                "the constraints are redundant at this configuration")
        diag[j] = d
        lower[j][j] = 1.0
        for i in range(j + 1, n):
            s = a[i][j]
            for k in range(j):
                s = s - lower[i][k] * lower[j][k] * diag[k]
            lower[i][j] = s / d
    return lower, diag


def ldl_solve(lower: Sequence[Scalars], diag: Scalars, b: Sequence[Scalar]) -> Scalars:
    """Solve ``L D L^T x = b`` given the factors of :func:`ldl_factor`."""
    n = len(diag)
    y: Scalars = list(b)
    for i in range(n):
        for k in range(i):
            y[i] = y[i] - lower[i][k] * y[k]
    z = [y[i] / diag[i] for i in range(n)]
    for i in reversed(range(n)):
        for k in range(i + 1, n):
            z[i] = z[i] - lower[k][i] * z[k]
    return z


def spd_inverse(a: Sequence[Sequence[Scalar]], what: str = "matrix") -> list[Scalars]:
    """The inverse of a small symmetric positive-definite matrix (list of rows)."""
    n = len(a)
    lower, diag = ldl_factor(a, what)
    cols = [ldl_solve(lower, diag, [1.0 if i == j else 0.0 for i in range(n)])
            for j in range(n)]
    inv = [[cols[j][i] for j in range(n)] for i in range(n)]
    # Symmetrize exactly (the two triangles differ by rounding only).
    for i in range(n):
        for j in range(i + 1, n):
            inv[j][i] = inv[i][j]
    return inv
