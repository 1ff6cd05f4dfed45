"""Up-front checks of a problem statement, with errors that name the offending piece."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence

from gaitopt.ocp.problem import ControlLinkage, Linkage, Phase, Problem


class ProblemError(ValueError):
    """A problem statement is inconsistent (the message names the phase/state/linkage)."""


def as_bound(value: tuple[float, float] | float, where: str) -> tuple[float, float]:
    """``(lower, upper)`` from a pair or a single value (lower == upper), checked."""
    if isinstance(value, tuple | list):
        if len(value) != 2:
            raise ProblemError(f"{where}: a bound must be (lower, upper), got {value!r}")
        lo, hi = float(value[0]), float(value[1])
    else:
        lo = hi = float(value)
    if math.isnan(lo) or math.isnan(hi):
        raise ProblemError(f"{where}: bound is NaN")
    if lo > hi:
        raise ProblemError(f"{where}: lower bound {lo} > upper bound {hi}")
    return lo, hi


def _unique(names: Iterable[str], what: str) -> None:
    seen: set[str] = set()
    for name in names:
        if not isinstance(name, str) or not name:
            raise ProblemError(f"{what}: names must be non-empty strings, got {name!r}")
        if name in seen:
            raise ProblemError(f"{what}: duplicate name {name!r}")
        seen.add(name)


def _check_names(mapping: Mapping[str, object], allowed: Sequence[str], what: str) -> None:
    for name in mapping:
        if name not in allowed:
            raise ProblemError(f"{what}: unknown name {name!r} (allowed: {list(allowed)})")


def _check_bounds(mapping: Mapping[str, object], allowed: Sequence[str], what: str) -> None:
    _check_names(mapping, allowed, what)
    for name, value in mapping.items():
        as_bound(value, f"{what} {name!r}")  # type: ignore[arg-type]


def check_phase(phase: Phase) -> None:
    """Check names, bounds, duration and intervals of one phase."""
    where = f"phase {phase.name!r}"
    _unique(phase.states, f"{where} states")
    _unique(phase.controls, f"{where} controls")
    if not phase.states:
        raise ProblemError(f"{where}: needs at least one state")
    if not callable(phase.dynamics):
        raise ProblemError(f"{where}: dynamics must be a callable f(x, u, p, t)")
    if phase.lagrange is not None and not callable(phase.lagrange):
        raise ProblemError(f"{where}: lagrange must be a callable L(x, u, p, t)")
    _check_bounds(phase.state_bounds, phase.states, f"{where} state_bounds")
    _check_bounds(phase.control_bounds, phase.controls, f"{where} control_bounds")
    _check_bounds(phase.initial_state, phase.states, f"{where} initial_state")
    _check_bounds(phase.final_state, phase.states, f"{where} final_state")
    _check_bounds(phase.initial_control, phase.controls, f"{where} initial_control")
    _check_bounds(phase.final_control, phase.controls, f"{where} final_control")
    _check_names(phase.control_rate_weights, phase.controls, f"{where} control_rate_weights")
    for name, r in phase.control_rate_weights.items():
        if not (r >= 0 and math.isfinite(r)):
            raise ProblemError(f"{where}: control_rate_weights[{name!r}] = {r!r}: must be "
                               "finite and >= 0")
    _check_names(phase.state_scales, phase.states, f"{where} state_scales")
    _check_names(phase.control_scales, phase.controls, f"{where} control_scales")
    for name, s in {**phase.state_scales, **phase.control_scales}.items():
        if not (s > 0 and math.isfinite(s)):
            raise ProblemError(f"{where}: scale of {name!r} must be finite and > 0, got {s}")
    try:
        dur = phase.duration_spec()
    except ValueError as exc:
        raise ProblemError(str(exc)) from None
    if dur.kind != "expression":
        lo, hi = as_bound((dur.lower, dur.upper), f"{where} duration")
        if lo < 0 or not math.isfinite(hi):
            raise ProblemError(f"{where} duration: bounds must satisfy 0 <= lower <= upper < inf,"
                               f" got ({lo}, {hi})")
        if dur.kind == "fixed" and lo <= 0:
            raise ProblemError(f"{where} duration: a fixed duration must be > 0, got {lo}")
    else:
        if not callable(dur.expression):
            raise ProblemError(f"{where} duration: expression must be a callable T(p)")
        as_bound((dur.lower, dur.upper), f"{where} duration")
    if int(phase.intervals) < 1:
        raise ProblemError(f"{where}: intervals must be >= 1, got {phase.intervals}")
    _unique([c.name for c in phase.path_constraints], f"{where} path constraints")
    for c in phase.path_constraints:
        if c.at not in ("knots", "knots+midpoints"):
            raise ProblemError(f"{where} path constraint {c.name!r}: at must be 'knots' or "
                               f"'knots+midpoints', got {c.at!r}")
        if not callable(c.fn):
            raise ProblemError(f"{where} path constraint {c.name!r}: fn must be callable")


def check_problem(problem: Problem) -> None:
    """Check a whole problem statement; raise :class:`ProblemError` naming the first fault."""
    if not problem.phases:
        raise ProblemError("problem: needs at least one phase")
    _unique([ph.name for ph in problem.phases], "problem phases")
    _unique(problem.parameter_names, "problem parameters")
    for ph in problem.phases:
        check_phase(ph)
    for par in problem.parameters:
        as_bound((par.lower, par.upper), f"parameter {par.name!r}")
        if par.scale is not None and not (par.scale > 0 and math.isfinite(par.scale)):
            raise ProblemError(f"parameter {par.name!r}: scale must be finite and > 0")
    if not (problem.objective_scale > 0 and math.isfinite(problem.objective_scale)):
        raise ProblemError(f"problem: objective_scale must be finite and > 0, "
                           f"got {problem.objective_scale}")
    phases = {ph.name: ph for ph in problem.phases}
    for link in problem.linkages:
        if not isinstance(link, Linkage | ControlLinkage):
            raise ProblemError(f"problem linkages: expected Linkage or ControlLinkage, got "
                               f"{type(link).__name__}")
        label = link.label()
        for end, name in (("from_phase", link.from_phase), ("to_phase", link.to_phase)):
            if name not in phases:
                raise ProblemError(f"{label}: {end} {name!r} is not a phase "
                                   f"(phases: {list(phases)})")
        src, dst = phases[link.from_phase], phases[link.to_phase]
        if isinstance(link, Linkage):
            targets = list(link.states) if link.states is not None else list(dst.states)
            _unique(targets, f"{label} states")
            for s in targets:
                if s not in dst.states:
                    raise ProblemError(f"{label}: state {s!r} is not a state of phase "
                                       f"{dst.name!r}")
                if link.jump is None and s not in src.states:
                    raise ProblemError(f"{label}: continuity of state {s!r} but phase "
                                       f"{src.name!r} has no such state (give a jump)")
        else:
            targets = list(link.controls) if link.controls is not None else list(dst.controls)
            _unique(targets, f"{label} controls")
            for s in targets:
                if s not in dst.controls:
                    raise ProblemError(f"{label}: control {s!r} is not a control of phase "
                                       f"{dst.name!r}")
                if link.fn is None and s not in src.controls:
                    raise ProblemError(f"{label}: continuity of control {s!r} but phase "
                                       f"{src.name!r} has no such control (give fn)")
    _unique([b.name for b in problem.boundary_constraints], "problem boundary constraints")
