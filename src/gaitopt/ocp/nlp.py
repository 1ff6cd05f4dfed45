"""Assembly of the sparse NLP of a transcription (symbolic, built once).

With w the unscaled decision vector (see :mod:`gaitopt.ocp.layout`), phase i of duration
``T_i`` starting at ``t0_i = t0 + sum_{j<i} T_j`` has knots ``t_k = t0_i + T_i tau_k``. The
phase's point function is mapped over the K knots (and, when needed, over the N midpoints
``t_k + h_k/2`` with the method's midpoint state and the averaged control), giving the defects,
the path constraints and the quadrature of the Lagrange integrand. For a method with midpoint
variables (separated Hermite-Simpson) the midpoint state is the variable ``x_m``, the point
function is mapped once over the K + N points, and the midpoint defects
``x_m - midpoint_state(x_k, x_{k+1}, f_k, f_{k+1}, h)`` are added after the defects. The
ends function adds the linkages, boundary constraints and the end/parameter costs::

    J = (sum_i quad_i(L_i) + M(ends, p) + P(p)) / D(ends, p)

The NLP handed to the solver is ``min J / objective_scale`` over ``w_hat = w / d_w`` subject to
``lbg / d_g <= g / d_g <= ubg / d_g``.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.functions import (
    EndsFunction,
    PhaseFunction,
    ends_with_knot_states,
    knot_point,
    with_knot_states,
)
from gaitopt.ocp.layout import ConstraintBlock, ConstraintLayout, Layout, PhaseLayout
from gaitopt.ocp.mesh import Mesh
from gaitopt.ocp.method import Method, midpoint_control
from gaitopt.ocp.problem import Phase, Problem

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Nlp:
    """The symbolic NLP and everything needed to scale and name it.

    ``w_hat`` (layout.size, 1) MX symbol; ``f`` scaled objective; ``g`` scaled constraints;
    ``evaluate`` maps unscaled w to ``(g unscaled, numerator, denominator, phase durations)``;
    ``dependent`` are the indices in w of the states given by
    :class:`~gaitopt.ocp.problem.KnotStates` (variables the NLP does not use) and
    ``knot_states`` maps unscaled w to their values.
    """

    w_hat: ca.MX
    f: ca.MX
    g: ca.MX
    layout: Layout
    constraints: ConstraintLayout
    d_w: Array
    d_g: Array
    lbg: Array
    ubg: Array
    objective_scale: float
    evaluate: ca.Function
    dependent: NDArray[np.int64]
    knot_states: ca.Function


class _Rows:
    """Accumulates constraint rows with names, bounds and scales."""

    def __init__(self) -> None:
        self.exprs: list[Any] = []
        self.blocks: list[ConstraintBlock] = []
        self.lower: list[Array] = []
        self.upper: list[Array] = []
        self.scale: list[Array] = []
        self.size = 0

    def add(self, name: str, phase: str | None, kind: str, expr: Any,
            shape: tuple[int, ...], lower: Array, upper: Array, scale: Array) -> None:
        rows = int(np.prod(shape))
        if rows == 0:
            return
        assert expr.shape == (rows, 1), (name, expr.shape, rows)
        assert lower.shape == upper.shape == scale.shape == (rows,), name
        self.exprs.append(expr)
        self.blocks.append(ConstraintBlock(name, phase, kind,
                                           slice(self.size, self.size + rows), shape))
        self.lower.append(lower)
        self.upper.append(upper)
        self.scale.append(scale)
        self.size += rows

    def cat(self, arrs: list[Array]) -> Array:
        return np.concatenate(arrs) if arrs else np.zeros(0)


def flat(m: Any) -> Any:
    """Column-major flattening of an (a, b) matrix to (a*b, 1): entry (i, j) -> row j*a + i."""
    return ca.reshape(m, m.numel(), 1)


#: How a point function of phase ``i`` is evaluated at M grid points:
#: ``(i, point, X (n, M), U (m, M), p (n_p, 1), t (1, M)) -> its outputs, one column per
#: point`` (``(xdot (n, M), path (r, M), L (1, M))`` for the phase's point function, and the
#: knot states as a fourth output for :func:`~gaitopt.ocp.functions.knot_point`). The default
#: maps the point function (:func:`mapped_points`); :mod:`gaitopt.ocp.pointwise` substitutes
#: symbols for the outputs instead.
PointCalls = Callable[[int, ca.Function, Any, Any, Any, Any], tuple[Any, ...]]


def mapped_points(i: int, point: ca.Function, X: Any, U: Any, p: Any, t: Any
                  ) -> tuple[Any, ...]:
    """The point function mapped over the M columns of ``X, U, t`` (one call per point)."""
    return tuple(point.map(int(X.shape[1]))(X, U, p, t))


#: How the ends function is evaluated: ``(fn, E (size, 1), p (n_p, 1)) -> (linkages,
#: boundary, mayer, parameter_cost, denominator)``. The default calls it
#: (:func:`called_ends`); :mod:`gaitopt.ocp.pointwise` substitutes symbols for the outputs.
EndsCall = Callable[[ca.Function, Any, Any], list[Any]]


def called_ends(fn: ca.Function, E: Any, p: Any) -> list[Any]:
    """The ends function called on ``E`` and ``p``."""
    return list(fn(E, p))


@dataclass(frozen=True)
class IntervalInputs:
    """What the terms of a phase's N intervals read (columns per interval): the knot states
    ``x_k, x_k1`` (n, N; the knot states of :class:`~gaitopt.ocp.problem.KnotStates` in
    place), the midpoint states ``xm`` (n, N; the separated form, else None), the dynamics
    ``f_k, f_k1, f_m`` and the integrand ``l_k, l_k1, l_m`` (1, N) at the knots and midpoints
    (``f_m``, ``l_m`` None where the method has no midpoints), the phase duration ``T``, and
    ``dtau`` (1, N), the normalised interval lengths (constants: h = T dtau).

    ``u_k, u_k1`` (m, N) are the knot controls and ``rates`` the weights of the control-rate
    term (:attr:`~gaitopt.ocp.problem.Phase.control_rate_weights`, a constant (m, 1); None
    without the term, and then the controls are not read).

    ``t_source`` (s, 1) and ``t_of`` give the duration as a function of a few entries of w:
    ``t_of(t_source)`` is ``T`` (the duration variable itself, the parameters of a duration
    expression, or nothing for a fixed duration), so that the terms of one interval are a
    function of a selection of w and of the point outputs (:mod:`gaitopt.ocp.pointwise`
    derives that function once and maps it over the intervals)."""

    method: Method
    x_k: Any
    x_k1: Any
    xm: Any
    f_k: Any
    f_k1: Any
    f_m: Any
    l_k: Any
    l_k1: Any
    l_m: Any
    T: Any
    dtau: ca.DM
    t_source: Any
    t_of: Callable[[Any], Any]
    u_k: Any = None
    u_k1: Any = None
    rates: ca.DM | None = None


def interval_terms(inp: IntervalInputs, T: Any, dtau: Any) -> tuple[Any, Any, Any]:
    """The defects (n, N), the midpoint defects (n, N; None without midpoint variables) and
    the cost of each interval (1, N): the quadrature of the integrand plus the control-rate
    term, for the intervals of ``inp`` with duration ``T`` and normalised interval lengths
    ``dtau`` (1, N)."""
    h = T * dtau
    Hn = ca.repmat(h, int(inp.x_k.shape[0]), 1)
    method = inp.method
    mid_defects = (None if inp.xm is None else
                   inp.xm - method.midpoint_state(inp.x_k, inp.x_k1, inp.f_k, inp.f_k1, Hn))
    defects = method.defects(inp.x_k, inp.x_k1, inp.f_k, inp.f_k1, inp.f_m, Hn)
    cost = method.quadrature(inp.l_k, inp.l_k1, inp.l_m, h)
    if inp.rates is not None:
        cost = cost + control_rates(inp.rates, inp.u_k, inp.u_k1, h)
    return defects, mid_defects, cost


#: How the terms of a phase's intervals are evaluated: ``(i, inputs) -> (defects,
#: midpoint defects or None, quadrature (1, N))``. The default computes them
#: (:func:`direct_intervals`); :mod:`gaitopt.ocp.pointwise` substitutes symbols instead.
IntervalCalls = Callable[[int, IntervalInputs], tuple[Any, Any, Any]]


def direct_intervals(i: int, inp: IntervalInputs) -> tuple[Any, Any, Any]:
    """The terms of the intervals as expressions (:func:`interval_terms`)."""
    return interval_terms(inp, inp.T, inp.dtau)


@dataclass(frozen=True)
class Assembly:
    """The NLP expressions in the symbol type they were built with (MX or SX)."""

    w_hat: Any
    f: Any
    g: Any
    g_unscaled: Any
    rows: _Rows
    numerator: Any
    denominator: Any
    durations: Any
    dependent_index: NDArray[np.int64]
    """Indices in w of the states given by :class:`~gaitopt.ocp.problem.KnotStates`."""
    dependent_values: Any
    """Their values (unscaled), an expression of ``w_hat``."""


def assemble(problem: Problem, method: Method, mesh: Mesh, layout: Layout,
             phase_fns: tuple[PhaseFunction, ...], ends_fn: EndsFunction, d_w: Array,
             state_scales: tuple[Array, ...]) -> Nlp:
    """Build the symbolic NLP (see the module docstring)."""
    a = assemble_expressions(problem, method, mesh, layout, phase_fns, ends_fn, d_w,
                             state_scales)
    rows = a.rows
    d_g = rows.cat(rows.scale)
    w_plain = ca.MX.sym("w_plain", layout.size)
    evaluate = ca.Function("evaluate", [a.w_hat],
                           [a.g_unscaled, a.numerator, a.denominator, a.durations])
    evaluate = ca.Function("evaluate_unscaled", [w_plain],
                           evaluate.call([w_plain / ca.DM(d_w)]),
                           ["w"], ["g", "numerator", "denominator", "durations"])
    knot_states = ca.Function("knot_states", [a.w_hat], [a.dependent_values])
    knot_states = ca.Function("knot_states_unscaled", [w_plain],
                              knot_states.call([w_plain / ca.DM(d_w)]), ["w"], ["values"])
    return Nlp(a.w_hat, a.f, a.g, layout,
               ConstraintLayout(tuple(rows.blocks), rows.size), d_w, d_g,
               rows.cat(rows.lower), rows.cat(rows.upper), problem.objective_scale, evaluate,
               a.dependent_index, knot_states)


def assemble_expressions(problem: Problem, method: Method, mesh: Mesh, layout: Layout,
                         phase_fns: tuple[PhaseFunction, ...], ends_fn: EndsFunction,
                         d_w: Array, state_scales: tuple[Array, ...], *,
                         symbols: Any = ca.MX, point_calls: PointCalls = mapped_points,
                         ends_call: EndsCall = called_ends, fold_knot_states: bool = False,
                         interval_calls: IntervalCalls = direct_intervals) -> Assembly:
    """The scaled objective and constraints as expressions of ``w_hat`` (a ``symbols``
    symbol: ``ca.MX`` or ``ca.SX``), the point functions evaluated by ``point_calls`` and the
    ends function by ``ends_call``.

    ``fold_knot_states``: the knot states of a phase with
    :class:`~gaitopt.ocp.problem.KnotStates` are computed inside the point function of its
    knots after the first (:func:`~gaitopt.ocp.functions.knot_point`, which also returns
    them) and inside the ends function (:func:`~gaitopt.ocp.functions.ends_with_knot_states`),
    from the state variables, instead of in the expressions around them: the same NLP, whose
    point inputs are then a selection of w and whose constraints are affine in the point
    outputs apart from the durations (what :mod:`gaitopt.ocp.pointwise` differentiates
    cheaply)."""
    sym = symbols
    w_hat = sym.sym("w", layout.size)
    w = w_hat * ca.DM(d_w)
    p = w[layout.parameter_start:layout.size]
    durations_expr = ends_fn.durations(p)
    rows = _Rows()
    numerator = sym(0.0)
    ends_parts: list[Any] = []
    durations: list[Any] = []
    dependent_index: list[int] = []
    dependent_values: list[Any] = []
    t_start = sym(problem.t0)
    folded_ends: list[tuple[int, PhaseFunction]] = []
    for i, (ph, pl, pf, tau) in enumerate(zip(problem.phases, layout.phases, phase_fns, mesh,
                                              strict=True)):
        spec = ph.duration_spec()
        n, K, N = ph.n_states, pl.knots, pl.intervals
        t_of: Callable[[Any], Any]
        if spec.kind == "expression":
            T = durations_expr[i]
            t_source, t_of = p, functools.partial(_duration_of, ends_fn.durations, i)
        elif pl.duration_index is not None:
            T = w[pl.duration_index]
            t_source, t_of = T, _itself
        else:
            T = sym(spec.lower)
            t_source, t_of = sym(0, 1), functools.partial(_constant, sym, float(spec.lower))
        durations.append(T)
        Z = ca.reshape(w[pl.knot_block()], pl.stride, K)
        X, U = Z[:n, :], Z[n:, :]
        fold = fold_knot_states and pf.knot_states is not None and K > 1
        if pf.knot_states is not None and K > 1 and not fold:
            X, index, values = _with_knot_states(
                pf, pl, X, pf.knot_states.map(K - 1)(X[:, 1:], p))
            dependent_index.extend(index)
            dependent_values.append(values)
        tk = t_start + T * ca.DM(tau).T
        tm = t_start + T * ca.DM(0.5 * (tau[:-1] + tau[1:])).T
        dtau = ca.DM(np.diff(tau)).T
        Um = midpoint_control(U[:, :-1], U[:, 1:])
        f_m = L_m = None
        # Separated form: one call of the point function per knot and per midpoint, all in
        # one map, at the variable midpoint states (no dynamics nested in dynamics).
        Xm = ca.reshape(w[pl.midpoint_block()], n, N) if method.midpoint_variables else None
        if fold:
            XD, C, L, X, index, values = _folded_knots(
                i, pf, pl, X, U, p, tk, point_calls, None if Xm is None else (Xm, Um, tm))
            dependent_index.extend(index)
            dependent_values.append(values)
        elif Xm is not None:
            XD, C, L = point_calls(i, pf.point, ca.horzcat(X, Xm), ca.horzcat(U, Um), p,
                                   ca.horzcat(tk, tm))
        else:
            XD, C, L = point_calls(i, pf.point, X, U, p, tk)
        if Xm is not None:
            f_m, Cm, L_m = XD[:, K:], C[:, K:], L[:, K:]
            XD, C, L = XD[:, :K], C[:, :K], L[:, :K]
        x_k, x_k1, f_k, f_k1 = X[:, :-1], X[:, 1:], XD[:, :-1], XD[:, 1:]
        x_mid = Xm
        if Xm is None and (method.needs_midpoint_dynamics or pf.midpoint_rows.size > 0):
            Xm = method.midpoint_state(x_k, x_k1, f_k, f_k1, ca.repmat(T * dtau, n, 1))
            f_m, Cm, L_m = point_calls(i, pf.point, Xm, Um, p, tm)
        defects, mid_defects, quadrature = interval_calls(i, IntervalInputs(
            method, x_k, x_k1, x_mid, f_k, f_k1, f_m, L[:, :-1], L[:, 1:], L_m, T, dtau,
            t_source, t_of, U[:, :-1], U[:, 1:], rate_weights(ph)))
        dx = state_scales[i]
        rows.add(f"{ph.name}/defects", ph.name, "defects", flat(defects), (N, n),
                 np.zeros(N * n), np.zeros(N * n), np.tile(dx, N))
        if mid_defects is not None:
            rows.add(f"{ph.name}/midpoint defects", ph.name, "defects", flat(mid_defects),
                     (N, n), np.zeros(N * n), np.zeros(N * n), np.tile(dx, N))
        r = pf.n_path
        rows.add(f"{ph.name}/path@knots", ph.name, "path", flat(C), (K, r),
                 np.tile(pf.path_lower, K), np.tile(pf.path_upper, K), np.tile(pf.path_scale, K))
        if pf.midpoint_rows.size:
            mr = pf.midpoint_rows
            rm = int(mr.size)
            rows.add(f"{ph.name}/path@midpoints", ph.name, "path", flat(Cm[list(mr), :]),
                     (N, rm), np.tile(pf.path_lower[mr], N), np.tile(pf.path_upper[mr], N),
                     np.tile(pf.path_scale[mr], N))
        if spec.kind == "expression" and (math.isfinite(spec.lower) or
                                          math.isfinite(spec.upper)):
            sc = max(abs(v) for v in (spec.lower, spec.upper) if math.isfinite(v)) or 1.0
            rows.add(f"{ph.name}/duration", ph.name, "duration", ca.reshape(T, 1, 1), (1,),
                     np.array([spec.lower]), np.array([spec.upper]), np.array([sc]))
        numerator = numerator + ca.sum2(quadrature)
        t_end = t_start + T
        if fold:  # the ends function computes the last knot's knot states itself
            folded_ends.append((ends_fn.ends_offsets[i] + 2 + n, pf))
            ends_parts += [t_start, t_end, X[:, 0], Z[:n, -1], U[:, 0], U[:, -1]]
        else:
            ends_parts += [t_start, t_end, X[:, 0], X[:, -1], U[:, 0], U[:, -1]]
        t_start = t_end
    E = ca.vertcat(*ends_parts)
    ends = ends_with_knot_states(ends_fn.fn, folded_ends) if folded_ends else ends_fn.fn
    link, bnd, mayer, pcost, den = ends_call(ends, E, p)
    for name, sl in ends_fn.linkage_rows:
        r = sl.stop - sl.start
        rows.add(name, None, "linkage", link[sl.start:sl.stop], (r,), np.zeros(r), np.zeros(r),
                 ends_fn.linkage_scale[sl])
    for name, sl in ends_fn.boundary_rows:
        r = sl.stop - sl.start
        rows.add(name, None, "boundary", bnd[sl.start:sl.stop], (r,),
                 ends_fn.boundary_lower[sl], ends_fn.boundary_upper[sl],
                 ends_fn.boundary_scale[sl])
    numerator = numerator + mayer + pcost
    J = numerator / den if ends_fn.has_denominator else numerator
    g = ca.vertcat(*rows.exprs) if rows.exprs else sym(0, 1)
    d_g = rows.cat(rows.scale)
    f_scaled = J / problem.objective_scale
    g_scaled = g / ca.DM(d_g) if rows.size else g
    return Assembly(w_hat, f_scaled, g_scaled, g, rows, numerator, den,
                    ca.vertcat(*durations), np.asarray(dependent_index, dtype=np.int64),
                    ca.vertcat(*dependent_values) if dependent_values else sym(0, 1))


def _duration_of(durations: ca.Function, i: int, p: Any) -> Any:
    """Phase ``i``'s duration from the parameters ``p``."""
    return durations(p)[i]


def _itself(x: Any) -> Any:
    return x


def _constant(sym: Any, value: float, _: Any) -> Any:
    return sym(value)


def control_rate_term(phase: Phase, U: Any, h: Any) -> Any:
    """``sum_j r_j sum_k (U[j, k+1] - U[j, k])^2 / h_k``: the exact ``sum_j r_j int u_j'^2 dt``
    of the piecewise-linear controls ``U`` (m, K) on intervals ``h`` (1, K - 1)
    (:attr:`~gaitopt.ocp.problem.Phase.control_rate_weights`); 0 without weights."""
    r = rate_weights(phase)
    if r is None or U.shape[1] < 2:
        return 0.0
    return ca.sum2(control_rates(r, U[:, :-1], U[:, 1:], h))


def rate_weights(phase: Phase) -> ca.DM | None:
    """The weights of the control-rate term by control (m, 1), None without weights."""
    weights = phase.control_rate_weights
    if not weights:
        return None
    return ca.DM([float(weights.get(name, 0.0)) for name in phase.controls])


def control_rates(r: ca.DM, u_k: Any, u_k1: Any, h: Any) -> Any:
    """The control-rate term of each interval, ``r^T (u_k1 - u_k)^2 / h`` (1, N)."""
    dU = u_k1 - u_k
    return ca.mtimes(r.T, dU * dU) / h


def _folded_knots(i: int, pf: PhaseFunction, pl: PhaseLayout, X: Any, U: Any, p: Any,
                  tk: Any, point_calls: PointCalls,
                  midpoints: tuple[Any, Any, Any] | None = None
                  ) -> tuple[Any, Any, Any, Any, list[int], Any]:
    """The point outputs ``(xdot, path, L)`` at the K knots (then at the midpoints
    ``(Xm, Um, tm)``, if given) of a phase with knot states, those of knots 1..K-1 from
    :func:`~gaitopt.ocp.functions.knot_point` on the state variables ``X`` (n, K); and, as
    ``_with_knot_states``, ``X`` with the knot states it returned, their indices in w
    and their values."""
    plain_x, plain_u, plain_t = X[:, :1], U[:, :1], tk[:, :1]
    if midpoints is not None:
        Xm, Um, tm = midpoints
        plain_x, plain_u, plain_t = (ca.horzcat(plain_x, Xm), ca.horzcat(plain_u, Um),
                                     ca.horzcat(plain_t, tm))
    XD0, C0, L0 = point_calls(i, pf.point, plain_x, plain_u, p, plain_t)
    XD1, C1, L1, values = point_calls(i, knot_point(pf), X[:, 1:], U[:, 1:], p, tk[:, 1:])
    X, index, flat_values = _with_knot_states(pf, pl, X, values)
    # Knot 0, knots 1..K-1, then the midpoints (the order of the unfolded call).
    XD = ca.horzcat(XD0[:, :1], XD1, XD0[:, 1:])
    C = ca.horzcat(C0[:, :1], C1, C0[:, 1:])
    L = ca.horzcat(L0[:, :1], L1, L0[:, 1:])
    return XD, C, L, X, index, flat_values


def _with_knot_states(pf: PhaseFunction, pl: PhaseLayout, X: Any, values: Any
                      ) -> tuple[Any, list[int], Any]:
    """``X`` (n, K) with the phase's knot states ``values`` (d, K-1) in place of their
    variables at knots 1..K-1, the indices in w of those variables and the values (a
    column, knot by knot)."""
    K = int(X.shape[1])
    X = ca.horzcat(X[:, :1], with_knot_states(pf, X[:, 1:], values))
    names = [pl.states[int(r)] for r in pf.knot_state_rows]
    index = [pl.index("state", name, k) for k in range(1, K) for name in names]
    return X, index, ca.vec(values)
