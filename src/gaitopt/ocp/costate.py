"""Costates (adjoint variables) estimated from the multipliers of the collocation defects.

The continuous problem's costate ``lambda(t)`` (n,) is defined with the Hamiltonian
``H(x, u, lambda, p, t) = L(x, u, p, t) + lambda^T f(x, u, p, t)`` (the integrand ``L`` divided
by the cost denominator ``D`` for a ratio cost): ``lambda' = -H_x``, ``H_u = 0`` where no
control bound or path constraint is active, and at a free final state ``lambda(tf) = M_x``.
Units: cost per unit of the state.

CasADi and IPOPT write the NLP's Lagrangian ``J + nu^T g + lam_x^T w`` (unscaled multipliers,
``Result.lam_g, lam_x``). Collect the terms of ONE interval ``k`` (length ``h``, knots ``z_k =
(x_k, u_k)``, ``z_{k+1}``, midpoint ``z_m``): its share of the quadrature, its defect row with
multiplier ``nu_k`` (n,), and in the separated Hermite-Simpson form its midpoint defect row
with multiplier ``mu_k`` (n,), and its midpoint path rows (multipliers ``pi_k``)::

    l_k = quadrature_k(L / D) + nu_k^T defect_k [+ mu_k^T middefect_k] + pi_k^T c(z_m)

Stationarity of the Lagrangian in the knot state ``x_k`` reads ``dl_{k-1}/dx_k + dl_k/dx_k +
(bounds and path rows at knot k) = 0``. The costate at the knots is read from it, one-sided::

    lambda_k^+ = + dl_k / dx_k          (from the interval after the knot, k = 0..N-1)
    lambda_k^- = - dl_{k-1} / dx_k      (from the interval before it,      k = 1..N)

They agree at a knot where no bound or path row is active (the discrete costate has a jump
exactly where the continuous one may have one); :func:`costates` returns ``lambda_0^+``,
``lambda_N^-`` and the mean of the two inside. At the phase ends the same stationarity makes
``lambda_0^+ = -(d Phi / d x_0)`` and ``lambda_N^- = d Phi / d x_N`` with ``Phi`` the Mayer
term plus the multipliers of the boundary rows and bounds: the transversality conditions.
With ``lam~_k = -nu_k`` (the defect multiplier approximates ``-lambda`` at the interval's
centre, sign flipped by CasADi's ``+ nu^T g`` and the defect's ``x_{k+1} - x_k - ...``):

* **trapezoidal** (Lobatto IIIA with two stages)::

      lambda_k^+     = lam~_k + (h/2) H_x(z_k, lam~_k)
      lambda_{k+1}^- = lam~_k - (h/2) H_x(z_{k+1}, lam~_k)

* **Hermite-Simpson, compressed** (Lobatto IIIA with three stages, weights 1/6, 2/3, 1/6,
  midpoint ``x_m = (x_k + x_{k+1})/2 + h (f_k - f_{k+1})/8``), with
  ``g_m = (2h/3) H_x(z_m, lam~_k) + c_x(z_m)^T pi_k``::

      lambda_k^+     = lam~_k + (h/6) H_x(z_k, lam~_k)     + (I/2 + (h/8) f_x(z_k))^T g_m
      lambda_{k+1}^- = lam~_k - (h/6) H_x(z_{k+1}, lam~_k) - (I/2 - (h/8) f_x(z_{k+1}))^T g_m

* **Hermite-Simpson, separated**: the same with ``g_m = -mu_k`` (stationarity in the midpoint
  variable ``x_m`` makes ``mu_k = -(2h/3) H_x(z_m) - c_x^T pi_k - lam_x(x_m)``: the two forms
  agree unless a midpoint state bound is active).

The derivatives are taken by CasADi from the phase's point function and the method's own
defect, midpoint and quadrature formulas, so they are those of the NLP that was solved.
Measured orders at the knots (docs/ocp.md, "Costates"): 2 for trapezoidal, 4 for both
Hermite-Simpson forms on a smooth problem. Phases with
:class:`~gaitopt.ocp.problem.KnotStates` (states given by others: the state vector is
constrained, so its costate is not determined by these rows alone) and phases of a single knot
are left out.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.functions import PhaseFunction
from gaitopt.ocp.method import Method, midpoint_control
from gaitopt.ocp.result import METHODS, Result
from gaitopt.ocp.validate import ProblemError

if TYPE_CHECKING:
    from gaitopt.ocp.transcription import Transcription

Array = NDArray[np.float64]


def interval_lagrangian(method: Method, pf: PhaseFunction, n: int, m: int, n_p: int
                        ) -> ca.Function:
    """``(lambda^+ at x_k, lambda^- at x_{k+1})`` (n, 1) each of one interval's Lagrangian
    ``l_k`` (module docstring) as a Function of ``x_k, u_k, x_{k+1}, u_{k+1}`` (n or m, 1),
    ``p`` (n_p, 1), ``t_k, h, sigma`` (1, 1; ``sigma = 1 / D`` weighs the integrand),
    ``nu`` (n, 1) defect multipliers, ``x_m, mu`` (n, 1; used by the separated form only) and
    ``pi`` (r_mid, 1) midpoint path multipliers."""
    xk, xk1, xm, nu, mu = (ca.SX.sym(s, n) for s in ("xk", "xk1", "xm", "nu", "mu"))
    uk, uk1 = ca.SX.sym("uk", m), ca.SX.sym("uk1", m)
    p, tk, h, sigma = ca.SX.sym("p", n_p), ca.SX.sym("tk"), ca.SX.sym("h"), ca.SX.sym("sigma")
    mid_rows = [int(r) for r in pf.midpoint_rows]
    pi = ca.SX.sym("pi", len(mid_rows))
    fk, _, lk = pf.point(xk, uk, p, tk)
    fk1, _, lk1 = pf.point(xk1, uk1, p, tk + h)
    interp = method.midpoint_state(xk, xk1, fk, fk1, h)
    ell = ca.SX(0.0)
    f_m, l_m = ca.SX.zeros(n), ca.SX(0.0)
    if method.midpoint_variables or method.needs_midpoint_dynamics or mid_rows:
        x_mid = xm if method.midpoint_variables else interp
        f_m, c_m, l_m = pf.point(x_mid, midpoint_control(uk, uk1), p, tk + h / 2)
        if mid_rows:
            ell += ca.dot(pi, c_m[mid_rows])
    if method.midpoint_variables:
        ell += ca.dot(mu, xm - interp)
    ell += sigma * method.quadrature(lk, lk1, l_m, h)
    ell += ca.dot(nu, method.defects(xk, xk1, fk, fk1, f_m, h))
    return ca.Function("interval_costates",
                       [xk, uk, xk1, uk1, p, tk, h, sigma, nu, xm, mu, pi],
                       [ca.gradient(ell, xk), -ca.gradient(ell, xk1)])


def one_sided_costates(tr: Transcription, result: Result) -> dict[str, tuple[Array, Array]]:
    """``{phase: (lambda_plus, lambda_minus)}``, each (K, n) by the phase's state order at its
    knots: ``lambda_plus[k]`` from the interval after knot k (NaN at the last knot),
    ``lambda_minus[k]`` from the interval before it (NaN at the first); see the module
    docstring. Unscaled, for the objective ``J`` as stated (a ratio cost included).

    Raises ProblemError when ``result`` was not solved by ``tr`` (method or layout differ)."""
    if result.method != tr.method or result.layout_signature != tr.layout.signature():
        raise ProblemError("costates: the result was not solved by this transcription "
                           f"(method {result.method!r} vs {tr.method!r}, or another layout)")
    method = METHODS[tr.method]
    blocks = {b.name: b for b in tr.nlp.constraints.blocks}
    p = result.w[tr.layout.parameter_slice()].reshape(-1, 1)
    n_p = p.shape[0]
    _, _, den, _ = (np.asarray(v, dtype=float).ravel() for v in tr.nlp.evaluate(result.w))
    sigma = 1.0 / float(den[0]) if tr.nlp_has_ratio else 1.0
    out: dict[str, tuple[Array, Array]] = {}
    for ph, pl, pf, traj in zip(tr.problem.phases, tr.layout.phases, tr.phase_functions,
                                result.phases, strict=True):
        n, m, N = ph.n_states, ph.n_controls, pl.intervals
        if pf.knot_states is not None or N == 0:
            continue

        def rows(suffix: str, width: int, name: str = ph.name, count: int = N) -> Array:
            block = blocks.get(f"{name}/{suffix}")
            if block is None:
                return np.zeros((width, count))
            return result.lam_g[block.rows].reshape(count, width).T
        nu = rows("defects", n)
        mu = rows("midpoint defects", n)
        pi = rows("path@midpoints", int(pf.midpoint_rows.size))
        x_mid = traj.x_mid.T if traj.x_mid is not None else np.zeros((n, N))
        h = np.diff(traj.t).reshape(1, N)
        fn = interval_lagrangian(method, pf, n, m, n_p).map(N)
        plus, minus = fn(traj.x[:-1].T, traj.u[:-1].T, traj.x[1:].T, traj.u[1:].T, p,
                         traj.t[:-1].reshape(1, N), h, sigma, nu, x_mid, mu, pi)
        lam_plus = np.full((N + 1, n), np.nan)
        lam_minus = np.full((N + 1, n), np.nan)
        lam_plus[:-1] = np.asarray(plus, dtype=float).T
        lam_minus[1:] = np.asarray(minus, dtype=float).T
        out[ph.name] = (lam_plus, lam_minus)
    return out


def costates(tr: Transcription, result: Result) -> dict[str, Array]:
    """The costate estimate ``lambda`` at each phase's knots, ``{phase: (K, n)}`` by the
    phase's state order (``K = N + 1`` knots, n states), with the sign convention
    ``H = L + lambda^T f``: ``lambda_0^+`` at the first knot, ``lambda_N^-`` at the last and
    the mean of the two one-sided values inside (module docstring; they differ only where a
    bound or path row is active at the knot). Phases with knot states or a single knot are
    left out. Raises ProblemError when ``result`` was not solved by ``tr``."""
    out = {}
    for name, (plus, minus) in one_sided_costates(tr, result).items():
        lam = 0.5 * (plus + minus)
        lam[0], lam[-1] = plus[0], minus[-1]
        out[name] = lam
    return out
