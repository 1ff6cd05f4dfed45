"""The problem's user callables, evaluated once on SX symbols and packed into CasADi Functions.

Per phase, ONE function evaluates everything needed at a grid point::

    point(x (n,1), u (m,1), p (n_p,1), t (1,1)) -> (xdot (n,1), path (r,1), lagrange (1,1))

with common subexpressions eliminated (``casadi.cse``), so work shared between the dynamics
and the path constraints (say a contact force) is done once; the transcription maps it over
the knots and the midpoints. One more function evaluates everything at the phase ends::

    ends(E, p) -> (linkages, boundary, mayer, parameter_cost, denominator)
    durations(p) -> (T_i(p) for each phase; 0 where the duration is not an expression)

where ``E`` stacks ``[t0, tf, x0 (n), xf (n), u0 (m), uf (m)]`` of every phase in order.
A phase with :class:`~gaitopt.ocp.problem.KnotStates` also has
``knot_states(x (n,1), p (n_p,1)) -> (values (d,1))``, the d states it gives at the knots
after the first, and their positions in ``x`` (``PhaseFunction.knot_state_rows``);
:func:`knot_point` and :func:`ends_with_knot_states` compute them inside the point function
and the ends function from the state variables (for :mod:`gaitopt.ocp.pointwise`).
"""

from __future__ import annotations

import math
import re
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.problem import ControlLinkage, Linkage, Phase, PhaseEnds, Problem
from gaitopt.ocp.validate import ProblemError

Array = NDArray[np.float64]


def c_name(text: str) -> str:
    """A valid C identifier derived from ``text`` (for Function names)."""
    out = re.sub(r"\W", "_", text)
    return out if out and not out[0].isdigit() else f"f_{out}"


def to_column(value: Any, where: str) -> ca.SX:
    """An SX column from an SX, a number or a list of them; errors name ``where``."""
    if isinstance(value, ca.MX):
        raise ProblemError(f"{where}: returned an MX expression; use SX (or SX Functions)")
    if isinstance(value, list | tuple):
        if len(value) == 0:
            return ca.SX(0, 1)
        try:
            value = ca.vertcat(*[ca.SX(v) if not isinstance(v, ca.SX) else v for v in value])
        except Exception as exc:  # noqa: BLE001 - report any conversion failure clearly
            raise ProblemError(f"{where}: cannot stack the returned list: {exc}") from None
    try:
        sx = ca.SX(value)
    except Exception as exc:  # noqa: BLE001
        raise ProblemError(f"{where}: returned {type(value).__name__}, expected an SX "
                           f"expression: {exc}") from None
    if sx.is_empty():
        return ca.SX(0, 1)
    if sx.shape[1] != 1:
        if sx.shape[0] == 1:
            sx = sx.T
        else:
            raise ProblemError(f"{where}: returned a {sx.shape} matrix, expected a column")
    return sx


def call_user(fn: Callable[..., Any], args: Sequence[Any], where: str) -> ca.SX:
    """Call a user callable, turning its exceptions into a :class:`ProblemError`."""
    try:
        value = fn(*args)
    except ProblemError:
        raise
    except Exception as exc:  # noqa: BLE001 - user code may raise anything
        raise ProblemError(f"{where} raised {type(exc).__name__}: {exc}") from exc
    return to_column(value, where)


def broadcast_bound(value: float | Sequence[float] | None, rows: int, where: str,
                    default: float) -> Array:
    """A bound/scale given as a scalar or a length-``rows`` sequence, as an array (rows,)."""
    if value is None:
        return np.full(rows, default)
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.size == 1:
        return np.full(rows, float(arr[0]))
    if arr.shape != (rows,):
        raise ProblemError(f"{where}: expected 1 or {rows} values, got {arr.size}")
    return arr


def cat(arrays: Sequence[Array]) -> Array:
    """Concatenate 1-D arrays (empty list: an empty array)."""
    return np.concatenate(list(arrays)) if len(arrays) else np.zeros(0)


def scale_from_bounds(lower: Array, upper: Array) -> Array:
    """Per-entry scale: the largest finite bound magnitude, or 1 (all finite, > 0)."""
    mags = np.where(np.isfinite(lower), np.abs(lower), 0.0)
    mags = np.maximum(mags, np.where(np.isfinite(upper), np.abs(upper), 0.0))
    return np.where(mags > 0.0, mags, 1.0)


@dataclass(frozen=True)
class PathRows:
    """Where one path constraint sits in the phase function's ``path`` output."""

    name: str
    rows: slice
    at: str


@dataclass(frozen=True)
class PhaseFunction:
    """The compiled-once point function of a phase and the metadata of its path output."""

    point: ca.Function
    path_rows: tuple[PathRows, ...]
    path_lower: Array
    path_upper: Array
    path_scale: Array
    midpoint_rows: NDArray[np.int64]
    knot_states: ca.Function | None = None
    knot_state_rows: NDArray[np.int64] = field(
        default_factory=lambda: np.zeros(0, dtype=np.int64))

    @property
    def n_path(self) -> int:
        """r: rows of path constraints at a knot."""
        return int(self.path_lower.size)


def build_phase_function(phase: Phase, n_p: int, *, cse: bool = True) -> PhaseFunction:
    """Evaluate the phase's callables on SX symbols and pack them (see module docstring)."""
    where = f"phase {phase.name!r}"
    n, m = phase.n_states, phase.n_controls
    x, u = ca.SX.sym("x", n), ca.SX.sym("u", m)
    p, t = ca.SX.sym("p", n_p), ca.SX.sym("t")
    xdot = call_user(phase.dynamics, (x, u, p, t), f"{where} dynamics")
    if xdot.shape[0] != n:
        raise ProblemError(f"{where} dynamics: returned {xdot.shape[0]} values but the phase "
                           f"has {n} states {list(phase.states)}")
    pieces, rows, lowers, uppers, scales = [], [], [], [], []
    pos = 0
    for c in phase.path_constraints:
        cw = f"{where} path constraint {c.name!r}"
        val = call_user(c.fn, (x, u, p, t), cw)
        r = val.shape[0]
        if r == 0:
            raise ProblemError(f"{cw}: returned no values")
        lo = broadcast_bound(c.lower, r, f"{cw} lower", -math.inf)
        hi = broadcast_bound(c.upper, r, f"{cw} upper", math.inf)
        if np.any(lo > hi) or np.any(np.isnan(lo)) or np.any(np.isnan(hi)):
            raise ProblemError(f"{cw}: lower bound > upper bound (or NaN): {lo} > {hi}")
        sc = (broadcast_bound(c.scale, r, f"{cw} scale", 1.0) if c.scale is not None
              else scale_from_bounds(lo, hi))
        if np.any(sc <= 0) or not np.all(np.isfinite(sc)):
            raise ProblemError(f"{cw}: scale must be finite and > 0")
        pieces.append(val)
        rows.append(PathRows(c.name, slice(pos, pos + r), c.at))
        lowers.append(lo)
        uppers.append(hi)
        scales.append(sc)
        pos += r
    path = ca.vertcat(*pieces) if pieces else ca.SX(0, 1)
    lag = (call_user(phase.lagrange, (x, u, p, t), f"{where} lagrange")
           if phase.lagrange is not None else ca.SX(1, 1))
    if lag.shape[0] != 1:
        raise ProblemError(f"{where} lagrange: must return a scalar, got {lag.shape[0]} values")
    outs = [xdot, path, lag]
    if cse:
        outs = list(ca.cse(outs))
    point = ca.Function(c_name(f"point_{phase.name}"), [x, u, p, t], outs,
                        ["x", "u", "p", "t"], ["xdot", "path", "lagrange"])
    mid = [i for pr in rows if pr.at == "knots+midpoints"
           for i in range(pr.rows.start, pr.rows.stop)]
    knot_fn, knot_rows = _knot_states(phase, x, p)
    return PhaseFunction(point, tuple(rows), cat(lowers), cat(uppers), cat(scales),
                         np.asarray(mid, dtype=np.int64), knot_fn, knot_rows)


def _knot_states(phase: Phase, x: ca.SX, p: ca.SX
                 ) -> tuple[ca.Function | None, NDArray[np.int64]]:
    """The phase's :class:`~gaitopt.ocp.problem.KnotStates` as ``(x, p) -> values`` and the
    positions of its states in ``x`` (None and no rows without one)."""
    spec = phase.knot_states
    if spec is None:
        return None, np.zeros(0, dtype=np.int64)
    where = f"phase {phase.name!r} knot_states"
    unknown = [n for n in spec.names if n not in phase.states]
    if unknown or not spec.names or len(set(spec.names)) != len(spec.names):
        raise ProblemError(f"{where}: names must be distinct states of the phase, got "
                           f"{list(spec.names)} (states: {list(phase.states)})")
    index = np.asarray([list(phase.states).index(n) for n in spec.names], dtype=np.int64)
    val = call_user(spec.fn, (x, p), where)
    if val.shape[0] != index.size:
        raise ProblemError(f"{where}: returned {val.shape[0]} values for {index.size} states "
                           f"{list(spec.names)}")
    if any(ca.depends_on(val, x[int(i)]) for i in index):
        raise ProblemError(f"{where}: the values of {list(spec.names)} must not depend on "
                           "those states")
    fn = ca.Function(c_name(f"knot_states_{phase.name}"), [x, p], [val], ["x", "p"],
                     ["values"])
    return fn, index


def with_knot_states(pf: PhaseFunction, x: Any, values: Any) -> Any:
    """``x`` (n, M) with its rows ``pf.knot_state_rows`` replaced by the knot states
    ``values`` (d, M), column by column (SX or MX)."""
    rows = {int(r): j for j, r in enumerate(pf.knot_state_rows)}
    return ca.vertcat(*[values[rows[r], :] if r in rows else x[r, :]
                        for r in range(int(x.shape[0]))])


class IdentityCache:
    """Values made from some objects, found again by the objects' identity (the cache keeps
    them alive, so an identity is not reused while its entry lives): the newest ``size``
    entries. The transcriptions of one problem on other meshes share its functions, so the
    functions made from them are made, and hashed, once."""

    def __init__(self, size: int = 16) -> None:
        self.size = size
        self._items: OrderedDict[tuple[Any, ...], tuple[tuple[Any, ...], Any]] = OrderedDict()

    def get(self, objects: tuple[Any, ...], make: Callable[[], Any]) -> Any:
        """The value for ``objects`` (compared by identity), made by ``make`` if missing."""
        plain = int | str | float | tuple
        key = tuple(o if isinstance(o, plain) else id(o) for o in objects)
        hit = self._items.get(key)
        if hit is not None and all(a == b if isinstance(b, plain) else a is b
                                   for a, b in zip(hit[0], objects, strict=True)):
            self._items.move_to_end(key)
            return hit[1]
        value = make()
        self._items[key] = (objects, value)
        while len(self._items) > self.size:
            self._items.popitem(last=False)
        return value


#: The knot-state point functions made from a problem's functions: a few problems' worth
#: (an entry keeps the problem's phase functions alive).
_MADE = IdentityCache(16)


def knot_point(pf: PhaseFunction) -> ca.Function:
    """The point function of a phase with knot states at its knots after the first, on the
    state variables: ``(x (n,1), u, p, t) -> (xdot, path, lagrange, values (d,1))`` where
    ``values = knot_states(x, p)`` replace the rows ``knot_state_rows`` of ``x`` before the
    point function is evaluated (they do not depend on those rows) and are returned too."""
    return _MADE.get(("knot_point", pf), lambda: _knot_point(pf))


def _knot_point(pf: PhaseFunction) -> ca.Function:
    assert pf.knot_states is not None
    point = pf.point
    x = ca.SX.sym("x", point.size1_in(0))
    u, p, t = (ca.SX.sym(name, point.size1_in(j)) for j, name in enumerate("upt", start=1))
    values = pf.knot_states(x, p)
    placed = with_knot_states(pf, x, values)
    return ca.Function(f"knot_{point.name()}", [x, u, p, t], [*point(placed, u, p, t), values],
                       ["x", "u", "p", "t"], [*point.name_out(), "knot_states"])


def ends_with_knot_states(fn: ca.Function, phases: Sequence[tuple[int, PhaseFunction]]
                          ) -> ca.Function:
    """The ends function ``fn(E, p)`` on phase ends whose final states are the state
    variables: for each ``(start, pf)`` in ``phases``, the knot states of ``pf`` replace their
    rows of the final state at ``E[start:start + n]`` (computed from it and ``p``) before
    ``fn`` is evaluated."""
    key = ("ends", fn, *[(start, id(pf)) for start, pf in phases], *[pf for _, pf in phases])
    return _MADE.get(key, lambda: _ends_with_knot_states(fn, phases))


def _ends_with_knot_states(fn: ca.Function, phases: Sequence[tuple[int, PhaseFunction]]
                           ) -> ca.Function:
    E = ca.SX.sym("E", fn.size1_in(0))
    p = ca.SX.sym("p", fn.size1_in(1))
    placed = E
    for start, pf in phases:
        assert pf.knot_states is not None
        xf = E[start:start + pf.point.size1_in(0)]
        placed = ca.vertcat(placed[:start], with_knot_states(pf, xf, pf.knot_states(xf, p)),
                            placed[start + xf.shape[0]:])
    return ca.Function(f"{fn.name()}_knot_states", [E, p], fn.call([placed, p]),
                       fn.name_in(), fn.name_out())


@dataclass(frozen=True)
class EndsFunction:
    """The function of phase ends and parameters, and the bounds of its constraint outputs."""

    fn: ca.Function
    durations: ca.Function
    ends_offsets: tuple[int, ...]
    """Start of each phase's ``[t0, tf, x0, xf, u0, uf]`` in E."""
    size: int
    linkage_rows: tuple[tuple[str, slice], ...]
    linkage_scale: Array
    boundary_rows: tuple[tuple[str, slice], ...]
    boundary_lower: Array
    boundary_upper: Array
    boundary_scale: Array
    has_denominator: bool


def _phase_ends(problem: Problem) -> tuple[ca.SX, dict[str, PhaseEnds], list[int]]:
    parts, ends, offsets = [], {}, []
    pos = 0
    for ph in problem.phases:
        n, m = ph.n_states, ph.n_controls
        sym = ca.SX.sym(f"E_{c_name(ph.name)}", 2 + 2 * n + 2 * m)
        offsets.append(pos)
        pos += sym.shape[0]
        parts.append(sym)
        ends[ph.name] = PhaseEnds(t0=sym[0], tf=sym[1], x0=sym[2:2 + n], xf=sym[2 + n:2 + 2 * n],
                                  u0=sym[2 + 2 * n:2 + 2 * n + m], uf=sym[2 + 2 * n + m:],
                                  states=tuple(ph.states), controls=tuple(ph.controls))
    return ca.vertcat(*parts), ends, offsets


def _linkage_residual(link: Linkage | ControlLinkage, problem: Problem,
                      ends: dict[str, PhaseEnds], p: ca.SX,
                      state_scales: dict[str, Array]) -> tuple[ca.SX, Array]:
    src = problem.phases[problem.phase_index(link.from_phase)]
    dst = problem.phases[problem.phase_index(link.to_phase)]
    e_src, e_dst = ends[src.name], ends[dst.name]
    label = link.label()
    if isinstance(link, Linkage):
        names = list(link.states) if link.states is not None else list(dst.states)
        target = ca.vertcat(*[e_dst.x0[dst.states.index(s)] for s in names])
        if link.jump is None:
            value = ca.vertcat(*[e_src.xf[src.states.index(s)] for s in names])
        else:
            value = call_user(link.jump, (e_src.xf, e_src.uf, p), f"{label} jump")
        scale = state_scales[dst.name][[list(dst.states).index(s) for s in names]]
        kind = "states"
    else:
        names = list(link.controls) if link.controls is not None else list(dst.controls)
        target = ca.vertcat(*[e_dst.u0[dst.controls.index(s)] for s in names])
        if link.fn is None:
            value = ca.vertcat(*[e_src.uf[src.controls.index(s)] for s in names])
        else:
            value = call_user(link.fn, (e_src.uf, p), f"{label} fn")
        scale = np.ones(len(names))
        kind = "controls"
    if value.shape[0] != len(names):
        raise ProblemError(f"{label}: returned {value.shape[0]} values but links {len(names)} "
                           f"{kind} {names} of phase {dst.name!r}")
    return target - value, np.asarray(scale, dtype=float)


def build_ends_function(problem: Problem, state_scales: dict[str, Array], *,
                        cse: bool = True) -> EndsFunction:
    """Evaluate linkages, boundary constraints and end/parameter costs on SX symbols.

    ``state_scales`` (by phase name, (n,)) scale the linkage rows like the states they set.
    """
    E, ends, offsets = _phase_ends(problem)
    p = ca.SX.sym("p", len(problem.parameters))
    link_vals, link_rows, link_scales = [], [], []
    pos = 0
    for link in problem.linkages:
        res, sc = _linkage_residual(link, problem, ends, p, state_scales)
        link_vals.append(res)
        link_rows.append((link.label(), slice(pos, pos + res.shape[0])))
        link_scales.append(sc)
        pos += res.shape[0]
    b_vals, b_rows, b_lo, b_hi, b_sc = [], [], [], [], []
    pos = 0
    for bc in problem.boundary_constraints:
        where = f"boundary constraint {bc.name!r}"
        val = call_user(bc.fn, (ends, p), where)
        r = val.shape[0]
        lo = broadcast_bound(bc.lower, r, f"{where} lower", -math.inf)
        hi = broadcast_bound(bc.upper, r, f"{where} upper", math.inf)
        if np.any(lo > hi):
            raise ProblemError(f"{where}: lower bound > upper bound: {lo} > {hi}")
        sc = (broadcast_bound(bc.scale, r, f"{where} scale", 1.0) if bc.scale is not None
              else scale_from_bounds(lo, hi))
        b_vals.append(val)
        b_rows.append((bc.name, slice(pos, pos + r)))
        b_lo.append(lo)
        b_hi.append(hi)
        b_sc.append(sc)
        pos += r

    def scalar(fn: Callable[..., Any] | None, args: Sequence[Any], where: str,
               default: float) -> ca.SX:
        if fn is None:
            return ca.SX(default)
        val = call_user(fn, args, where)
        if val.shape[0] != 1:
            raise ProblemError(f"{where}: must return a scalar, got {val.shape[0]} values")
        return val

    mayer = scalar(problem.mayer, (ends, p), "problem mayer cost", 0.0)
    pcost = scalar(problem.parameter_cost, (p,), "problem parameter_cost", 0.0)
    den = scalar(problem.cost_denominator, (ends, p), "problem cost_denominator", 1.0)
    durs = []
    for ph in problem.phases:
        spec = ph.duration_spec()
        if spec.expression is not None:
            durs.append(scalar(spec.expression, (p,), f"phase {ph.name!r} duration", 0.0))
        else:
            durs.append(ca.SX(0.0))
    outs = [ca.vertcat(*link_vals) if link_vals else ca.SX(0, 1),
            ca.vertcat(*b_vals) if b_vals else ca.SX(0, 1),
            mayer, pcost, den]
    if cse:
        outs = list(ca.cse(outs))
    fn = ca.Function("ends", [E, p], outs, ["E", "p"],
                     ["linkages", "boundary", "mayer", "parameter_cost", "denominator"])
    dur_fn = ca.Function("durations", [p], [ca.vertcat(*durs)], ["p"], ["T"])
    return EndsFunction(fn, dur_fn, tuple(offsets), int(E.shape[0]), tuple(link_rows),
                        cat(link_scales), tuple(b_rows), cat(b_lo), cat(b_hi), cat(b_sc),
                        problem.cost_denominator is not None)
