"""Per-interval error estimate: the dynamics residual of the interpolant, integrated.

For interval k of a phase and state j::

    eta_kj = int_{t_k}^{t_{k+1}} | xdot_interp_j(t) - f_j(x_interp(t), u_interp(t), p, t) | dt

with the transcription's own interpolants (cubic Hermite states for Hermite-Simpson, quadratic
for trapezoidal; linear controls). The residual vanishes at the collocation points, so each
half interval is integrated separately with Gauss-Legendre quadrature. The scalar error of an
interval is ``max_j eta_kj / (1 + max_k |x_kj|)`` (relative to the state's size, as in Betts).
"""

from __future__ import annotations

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.method import Method, control_at

Array = NDArray[np.float64]

GAUSS_POINTS = 5


def interval_errors(method: Method, point: ca.Function, t: Array, x: Array, u: Array,
                    xdot: Array, p: Array) -> tuple[Array, Array]:
    """``(eta (N, n), error (N,))`` for one phase.

    ``t`` (K,), ``x`` (K, n), ``u`` (K, m), ``xdot`` (K, n) the dynamics at the knots,
    ``p`` (n_p,); ``point`` the phase point function.
    """
    K, n = x.shape
    N = K - 1
    nodes, weights = np.polynomial.legendre.leggauss(GAUSS_POINTS)
    # Two halves of [0, 1]: fractions s and weights (as fractions of h).
    s = np.concatenate([0.25 + 0.25 * nodes, 0.75 + 0.25 * nodes])
    ws = np.concatenate([0.25 * weights, 0.25 * weights])
    h = np.diff(t)  # (N,)
    S = s[None, :, None]  # (1, Q, 1)
    H = h[:, None, None]
    xk, xk1 = x[:-1, None, :], x[1:, None, :]
    fk, fk1 = xdot[:-1, None, :], xdot[1:, None, :]
    xs = method.state_at(S, xk, xk1, fk, fk1, H)  # (N, Q, n)
    rs = method.rate_at(S, xk, xk1, fk, fk1, H)
    us = control_at(S, u[:-1, None, :], u[1:, None, :])  # (N, Q, m)
    ts = t[:-1, None] + s[None, :] * h[:, None]  # (N, Q)
    Q = s.size
    M = N * Q
    f = np.asarray(point.map(M)(xs.reshape(M, n).T, us.reshape(M, u.shape[1]).T,
                                np.asarray(p, dtype=float).reshape(-1, 1),
                                ts.reshape(1, M))[0], dtype=float).T.reshape(N, Q, n)
    eta = np.einsum("q,kqj->kj", ws, np.abs(rs - f)) * h[:, None]
    size = 1.0 + np.max(np.abs(x), axis=0)
    return eta, np.max(eta / size[None, :], axis=1)
