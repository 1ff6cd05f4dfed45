"""``gaitopt.analysis.numeric``: CasADi functions on float arrays through the function buffer
give exactly what ``f(*args)`` gives, for column, matrix and scalar inputs and for dense and
sparse outputs, and refuse a sparse input."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from gaitopt.analysis.numeric import NumericFunction, evaluate


def _function() -> ca.Function:
    x = ca.SX.sym("x", 3)
    m = ca.SX.sym("m", 2, 3)
    s = ca.SX.sym("s")
    y = ca.vertcat(ca.sin(x[0]) * s, x[1] * x[2], ca.exp(-x[2]))
    out_matrix = ca.mtimes(m, x) * s
    # A sparse output: a diagonal with one structural zero's place left out.
    sparse = ca.SX(ca.Sparsity.diag(3))
    sparse[0, 0], sparse[2, 2] = x[0] ** 2, m[1, 2] + s
    return ca.Function("f", [x, m, s], [y, out_matrix, sparse, ca.jacobian(y, x)])


def test_values_equal_the_call() -> None:
    f = _function()
    rng = np.random.default_rng(3)
    numeric = NumericFunction(f)
    for _ in range(5):
        x, m, s = rng.normal(size=3), rng.normal(size=(2, 3)), float(rng.normal())
        got = numeric(x, m, s)
        want = [np.asarray(ca.densify(v), dtype=float) for v in f(x, m, s)]
        assert [g.shape for g in got] == [w.shape for w in want]
        for g, w in zip(got, want, strict=True):
            np.testing.assert_array_equal(g, w)


def test_outputs_are_fresh_arrays() -> None:
    """A returned array is not overwritten by the next call (callers keep them)."""
    f = _function()
    first = evaluate(f, np.ones(3), np.ones((2, 3)), 1.0)[0].copy()
    kept = evaluate(f, np.ones(3), np.ones((2, 3)), 1.0)[0]
    evaluate(f, np.zeros(3), np.zeros((2, 3)), 0.0)
    np.testing.assert_array_equal(kept, first)


def test_sparse_input_refused() -> None:
    x = ca.SX.sym("x", ca.Sparsity.diag(2))
    f = ca.Function("g", [x], [ca.sum1(ca.sum2(x))])
    with pytest.raises(ValueError, match="input 0 is sparse"):
        NumericFunction(f)
