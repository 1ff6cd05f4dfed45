"""Initial guesses: defaults from the bounds, user trajectories, or an earlier result.

A :class:`Guess` gives, per phase, values on normalised times ``tau`` in [0, 1] (interpolated
linearly onto the knots) and durations and parameters by name; anything missing falls back to
the default. A :class:`~gaitopt.ocp.result.Result` is also a guess: its trajectories are
evaluated with its own interpolants at the new knots (same normalised times, so a different
mesh or number of intervals is fine). Midpoint state variables (separated Hermite-Simpson)
get the same guess evaluated at the interval midpoints, so a Result of either Hermite-Simpson
form starts the other one at a point that satisfies the midpoint defects.

Defaults: a state goes linearly from its fixed initial value (or its path default) to its fixed
final value (or the start value); the path default is the midpoint of finite path bounds, else
0 clipped into the bounds. Controls and parameters: the midpoint of finite bounds, else 0
clipped; free durations: the guess, else the midpoint of the bounds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gaitopt.ocp.layout import Layout
from gaitopt.ocp.mesh import Mesh
from gaitopt.ocp.problem import Phase, Problem
from gaitopt.ocp.result import Result
from gaitopt.ocp.validate import ProblemError, as_bound

Array = NDArray[np.float64]

Values = ArrayLike | Mapping[str, ArrayLike] | None
"""(M, n) array in name order, or values by name (each (M,) or a scalar)."""


@dataclass(frozen=True)
class PhaseGuess:
    """Guess for one phase: ``x``/``u`` given at normalised times ``tau`` (M,).

    ``tau`` defaults to M equally spaced points on [0, 1].
    """

    x: Values = None
    u: Values = None
    tau: ArrayLike | None = None
    duration: float | None = None


@dataclass(frozen=True)
class Guess:
    """Guess for a whole problem: phases and parameters by name."""

    phases: Mapping[str, PhaseGuess] = field(default_factory=dict)
    parameters: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class WarmStart:
    """A solved NLP point to restart from exactly: the unscaled values ``w`` (n_w,) and the
    multipliers ``lam_x`` (n_w,), ``lam_g`` (n_g,) of a transcription with the layout
    ``layout`` (``repr`` of :meth:`~gaitopt.ocp.layout.Layout.signature`) and ``method``.

    Unlike a :class:`Guess` it holds no trajectories: it fits only a transcription with the
    same layout and method (anything else is a :class:`ProblemError`). Saved gaits keep one
    (:func:`warm_start_of`), so a warm start from a file restarts IPOPT with its
    multipliers, as a warm start from a Result in the same process does."""

    w: Array
    lam_x: Array
    lam_g: Array
    layout: str
    method: str

    def fits(self, layout: Layout, method: str, n_g: int) -> bool:
        """Whether this point belongs to a transcription with ``layout``, ``method`` and
        ``n_g`` constraints."""
        return (self.layout == repr(layout.signature()) and self.method == method
                and self.w.size == layout.size and self.lam_g.size == n_g)


def warm_start_of(result: Result) -> WarmStart:
    """The :class:`WarmStart` of a solved result (its values and multipliers)."""
    return WarmStart(w=np.asarray(result.w, dtype=float), lam_x=np.asarray(result.lam_x,
                                                                            dtype=float),
                     lam_g=np.asarray(result.lam_g, dtype=float),
                     layout=repr(result.layout_signature), method=result.method)


def secant_start(before: Result, last: Result, ratio: float) -> WarmStart:
    """The secant prediction of a solution one more step along a continuation:
    ``last + ratio (last - before)`` for the values ``w`` and the multipliers ``lam_x,
    lam_g`` alike, ``before`` and ``last`` the solutions at the parameter values ``p_0, p_1``
    and ``ratio = (p_2 - p_1) / (p_1 - p_0)`` for the next value ``p_2`` (1 for equal steps).
    Both must be of one transcription (layout, method and constraint count); IPOPT moves a
    predicted value that leaves its bounds back inside.

    Raises:
        ProblemError: the two results are of different transcriptions, or ``ratio`` is not
            finite.
    """
    if (before.layout_signature != last.layout_signature or before.method != last.method
            or before.w.size != last.w.size or before.lam_g.size != last.lam_g.size):
        raise ProblemError("secant_start: the two results are of different transcriptions")
    if not math.isfinite(ratio):
        raise ProblemError(f"secant_start: ratio = {ratio}: need a finite step ratio")
    a, b = warm_start_of(before), warm_start_of(last)
    return WarmStart(w=b.w + ratio * (b.w - a.w), lam_x=b.lam_x + ratio * (b.lam_x - a.lam_x),
                     lam_g=b.lam_g + ratio * (b.lam_g - a.lam_g), layout=b.layout,
                     method=b.method)


def default_value(lo: float, hi: float) -> float:
    """Midpoint of finite bounds, else 0 clipped into them."""
    if math.isfinite(lo) and math.isfinite(hi):
        return 0.5 * (lo + hi)
    return float(np.clip(0.0, lo, hi))


def _fixed(mapping: Mapping[str, object], name: str, where: str) -> float | None:
    if name not in mapping:
        return None
    lo, hi = as_bound(mapping[name], where)  # type: ignore[arg-type]
    return lo if lo == hi else default_value(lo, hi)


def _default_states(ph: Phase, tau: Array) -> Array:
    out = np.zeros((tau.size, ph.n_states))
    for j, name in enumerate(ph.states):
        lo, hi = as_bound(ph.state_bounds.get(name, (-math.inf, math.inf)), name)
        mid = default_value(lo, hi)
        a = _fixed(ph.initial_state, name, f"phase {ph.name!r} initial_state {name!r}")
        b = _fixed(ph.final_state, name, f"phase {ph.name!r} final_state {name!r}")
        a = mid if a is None else a
        b = a if b is None else b
        out[:, j] = a + (b - a) * tau
    return out


def _default_controls(ph: Phase, tau: Array) -> Array:
    out = np.zeros((tau.size, ph.n_controls))
    for j, name in enumerate(ph.controls):
        lo, hi = as_bound(ph.control_bounds.get(name, (-math.inf, math.inf)), name)
        out[:, j] = default_value(lo, hi)
    return out


def _user_values(values: Values, names: tuple[str, ...], tau_knots: Array,
                 tau_given: ArrayLike | None, base: Array, where: str) -> Array:
    if values is None:
        return base
    out = base.copy()
    if isinstance(values, Mapping):
        for name, val in values.items():
            if name not in names:
                raise ProblemError(f"{where}: unknown name {name!r} (allowed: {list(names)})")
            arr = np.atleast_1d(np.asarray(val, dtype=float))
            tg = (np.linspace(0, 1, arr.size) if tau_given is None
                  else np.asarray(tau_given, dtype=float))
            if arr.size == 1:
                out[:, names.index(name)] = arr[0]
            elif arr.size != tg.size:
                raise ProblemError(f"{where} {name!r}: {arr.size} values for {tg.size} times")
            else:
                out[:, names.index(name)] = np.interp(tau_knots, tg, arr)
        return out
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 1 and len(names) == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[1] != len(names):
        raise ProblemError(f"{where}: expected an (M, {len(names)}) array for {list(names)}, "
                           f"got shape {arr.shape}")
    tg = (np.linspace(0, 1, arr.shape[0]) if tau_given is None
          else np.asarray(tau_given, dtype=float))
    if tg.size != arr.shape[0]:
        raise ProblemError(f"{where}: {arr.shape[0]} rows for {tg.size} times tau")
    for j in range(len(names)):
        out[:, j] = np.interp(tau_knots, tg, arr[:, j])
    return out


def _from_result(res: Result, ph: Phase, index: int, tau: Array,
                 x: Array, u: Array) -> tuple[Array, Array, float | None]:
    try:
        old = res.phase(ph.name)
    except KeyError:
        if index >= len(res.phases):
            return x, u, None
        old = res.phase(index)
    t_new = old.t0 + old.duration * tau
    xs, us = old.x_at(t_new), old.u_at(t_new)
    for j, name in enumerate(ph.states):
        if name in old.states:
            x[:, j] = xs[:, old.states.index(name)]
    for j, name in enumerate(ph.controls):
        if name in old.controls:
            u[:, j] = us[:, old.controls.index(name)]
    return x, u, old.duration


def _phase_values(guess: Guess | Result | None, ph: Phase, index: int, tau: Array,
                  duration: float | None) -> tuple[Array, Array, float | None]:
    """States (M, n), controls (M, m) at normalised times ``tau`` (M,) and the duration of
    phase ``ph`` (position ``index``) from ``guess``, on top of the defaults."""
    x, u = _default_states(ph, tau), _default_controls(ph, tau)
    if isinstance(guess, Result):
        x, u, d = _from_result(guess, ph, index, tau, x, u)
        duration = d if d is not None else duration
    elif isinstance(guess, Guess) and ph.name in guess.phases:
        pg = guess.phases[ph.name]
        where = f"guess for phase {ph.name!r}"
        x = _user_values(pg.x, tuple(ph.states), tau, pg.tau, x, f"{where} x")
        u = _user_values(pg.u, tuple(ph.controls), tau, pg.tau, u, f"{where} u")
        duration = pg.duration if pg.duration is not None else duration
    return x, u, duration


def guess_vector(problem: Problem, layout: Layout, mesh: Mesh,
                 guess: Guess | Result | None) -> Array:
    """The unscaled initial point w0 (layout.size,) from ``guess`` (see module docstring)."""
    w = np.zeros(layout.size)
    if isinstance(guess, Guess):
        names = [ph.name for ph in problem.phases]
        for name in guess.phases:
            if name not in names:
                raise ProblemError(f"guess: {name!r} is not a phase (phases: {names})")
        for name in guess.parameters:
            if name not in layout.parameters:
                raise ProblemError(f"guess: {name!r} is not a parameter "
                                   f"(parameters: {list(layout.parameters)})")
    for i, (ph, pl, tau) in enumerate(zip(problem.phases, layout.phases, mesh, strict=True)):
        spec = ph.duration_spec()
        x, u, dur = _phase_values(guess, ph, i, tau, spec.guess)
        w[pl.state_indices()] = x
        if ph.n_controls:
            w[pl.control_indices()] = u
        if pl.midpoints:
            # Midpoint states (separated Hermite-Simpson): the same guess at the midpoints.
            x_mid, _, _ = _phase_values(guess, ph, i, 0.5 * (tau[:-1] + tau[1:]), spec.guess)
            w[pl.midpoint_indices()] = x_mid
        if pl.duration_index is not None:
            if dur is None:
                dur = default_value(spec.lower, spec.upper)
            w[pl.duration_index] = float(np.clip(dur, spec.lower, spec.upper))
    for par in problem.parameters:
        val: float | None = par.guess
        if isinstance(guess, Result) and par.name in guess.parameters:
            val = guess.parameters[par.name]
        elif isinstance(guess, Guess) and par.name in guess.parameters:
            val = float(guess.parameters[par.name])
        if val is None:
            val = default_value(par.lower, par.upper)
        w[layout.parameter(par.name)] = val
    return w
