"""CasADi functions evaluated on float arrays without CasADi's matrix conversions.

``f(*args)`` on NumPy arrays converts every input to a CasADi ``DM`` and every output back;
for a small function called thousands of times (a right-hand side inside SciPy's integrators)
the conversions take longer than the evaluation. :class:`NumericFunction` evaluates through
CasADi's function buffer instead: the inputs are copied into arrays the buffer reads and the
outputs' nonzeros are written into arrays the buffer owns, then returned dense. The values
are the same as ``f(*args)``'s (the same evaluation; measured in docs/stability.md, "Speed",
and docs/outputs.md, section 5, "Speed").
"""

from __future__ import annotations

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.functions import IdentityCache

Array = NDArray[np.float64]


class NumericFunction:
    """``f``'s outputs on float arrays (each dense, shape ``f.size_out(i)``) through CasADi's
    function buffer. Every input of ``f`` must be dense (a column or matrix given in
    column-major order, as CasADi stores it).

    Raises:
        ValueError: an input of ``f`` is sparse.
    """

    def __init__(self, f: ca.Function) -> None:
        self._buffer, self._run = f.buffer()
        self._inputs: list[Array] = []
        for i in range(f.n_in()):
            values = np.zeros(f.sparsity_in(i).nnz())
            if values.size != f.numel_in(i):
                raise ValueError(f"{f.name()}: input {i} is sparse")
            # The buffer's byte size is read from the memoryview (the stubs' third argument
            # is not accepted at run time).
            self._buffer.set_arg(i, memoryview(values))  # type: ignore[call-arg,arg-type]
            self._inputs.append(values)
        # Per output: its nonzeros, its shape, and where they go in the dense matrix (None for
        # a dense output, whose nonzeros are the matrix in column-major order).
        self._outputs: list[tuple[Array, tuple[int, int], tuple[Array, Array] | None]] = []
        for i in range(f.n_out()):
            pattern = f.sparsity_out(i)
            nonzeros = np.zeros(pattern.nnz())
            self._buffer.set_res(i, memoryview(nonzeros))  # type: ignore[call-arg,arg-type]
            rows, cols = pattern.get_triplet()
            places = None if pattern.is_dense() else (np.asarray(rows, dtype=int),
                                                      np.asarray(cols, dtype=int))
            self._outputs.append((nonzeros, pattern.shape, places))

    def __call__(self, *args: Array | float) -> list[Array]:
        for values, arg in zip(self._inputs, args, strict=True):
            values[:] = np.asarray(arg, dtype=float).ravel(order="F")
        self._run()
        out = []
        for nonzeros, shape, places in self._outputs:
            if places is None:
                out.append(nonzeros.reshape(shape, order="F").copy())
            else:
                dense = np.zeros(shape)
                dense[places] = nonzeros
                out.append(dense)
        return out


#: The :class:`NumericFunction` of each function in use (found by the function's identity).
_NUMERIC = IdentityCache(64)


def numeric_function(f: ca.Function) -> NumericFunction:
    """The :class:`NumericFunction` of ``f`` (one per function, kept while it is in use): a
    caller that evaluates ``f`` many times in a row takes it once."""
    numeric: NumericFunction = _NUMERIC.get((f,), lambda: NumericFunction(f))
    return numeric


def evaluate(f: ca.Function, *args: Array | float) -> list[Array]:
    """``f(*args)`` as float arrays (2-D, ``f.size_out(i)``), through
    :func:`numeric_function`."""
    return numeric_function(f)(*args)
