"""Bounds on the decision variables w and constraints g, with named, immutable overrides.

A :class:`Bounds` holds unscaled ``lbw, ubw`` (layout.size,) and ``lbg, ubg`` (constraints.size,)
and is changed only by the ``with_*`` methods, which return a new object. Passing one to
``Transcription.solve`` re-solves the same NLP with other bounds without rebuilding it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from gaitopt.ocp.layout import ConstraintLayout, Layout
from gaitopt.ocp.problem import Problem
from gaitopt.ocp.validate import ProblemError, as_bound

Array = NDArray[np.float64]


def _pair(lower: float, upper: float | None, where: str) -> tuple[float, float]:
    return as_bound((lower, lower if upper is None else upper), where)


@dataclass(frozen=True)
class Bounds:
    """Unscaled bounds of an NLP; ``with_*`` return modified copies."""

    layout: Layout
    constraints: ConstraintLayout
    lbw: Array
    ubw: Array
    lbg: Array
    ubg: Array
    midpoint_bounds: bool = True
    """Whether whole-phase state bounds also hold at the midpoint states (separated form)."""

    def _set_w(self, index: int | slice | NDArray[np.int64], lo: float, hi: float) -> Bounds:
        lbw, ubw = self.lbw.copy(), self.ubw.copy()
        lbw[index], ubw[index] = lo, hi
        return replace(self, lbw=lbw, ubw=ubw)

    def with_parameter(self, name: str, lower: float, upper: float | None = None) -> Bounds:
        """Bound parameter ``name`` (``upper=None`` fixes it to ``lower``)."""
        lo, hi = _pair(lower, upper, f"parameter {name!r}")
        return self._set_w(self.layout.parameter(name), lo, hi)

    def with_duration(self, phase: str, lower: float, upper: float | None = None) -> Bounds:
        """Bound the free duration of ``phase``."""
        lo, hi = _pair(lower, upper, f"phase {phase!r} duration")
        return self._set_w(self.layout.index(phase, "duration"), lo, hi)

    def with_state(self, phase: str, name: str, lower: float, upper: float | None = None,
                   knot: int | None = None) -> Bounds:
        """Bound state ``name`` of ``phase`` at one knot or (``knot=None``) along the phase:
        at all knots and, in the separated Hermite-Simpson form with ``midpoint_bounds``, at
        all midpoint states."""
        lo, hi = _pair(lower, upper, f"phase {phase!r} state {name!r}")
        pl = self.layout.phase(phase)
        if knot is not None:
            return self._set_w(pl.index("state", name, knot), lo, hi)
        out = self._set_w(pl.across_knots("state", name), lo, hi)
        return out._set_w(pl.across_midpoints(name), lo, hi) if self.midpoint_bounds else out

    def with_control(self, phase: str, name: str, lower: float, upper: float | None = None,
                     knot: int | None = None) -> Bounds:
        """Bound control ``name`` of ``phase`` at one knot or at all knots."""
        lo, hi = _pair(lower, upper, f"phase {phase!r} control {name!r}")
        pl = self.layout.phase(phase)
        idx = (pl.across_knots("control", name) if knot is None
               else pl.index("control", name, knot))
        return self._set_w(idx, lo, hi)

    def with_constraint(self, block: str, lower: float, upper: float | None = None) -> Bounds:
        """Bound every row of constraint block ``block`` (e.g. a boundary constraint name)."""
        lo, hi = _pair(lower, upper, f"constraint {block!r}")
        rows = self.constraints.block(block).rows
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        lbg[rows], ubg[rows] = lo, hi
        return replace(self, lbg=lbg, ubg=ubg)

    def with_rows(self, rows: NDArray[np.int64] | slice, lower: float | NDArray[np.float64],
                  upper: float | NDArray[np.float64]) -> Bounds:
        """Bound the constraint rows ``rows`` of g (see ``Transcription.path_rows``)."""
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        lbg[rows], ubg[rows] = lower, upper
        return replace(self, lbg=lbg, ubg=ubg)

    def check(self) -> None:
        """Raise :class:`ProblemError` naming the first variable/row with lower > upper."""
        bad = np.flatnonzero(self.lbw > self.ubw)
        if bad.size:
            raise ProblemError(f"variable bounds: lower > upper at {describe(self.layout, bad[0])}")
        bad = np.flatnonzero(self.lbg > self.ubg)
        if bad.size:
            names = self.constraints.row_names()
            raise ProblemError(f"constraint bounds: lower > upper at {names[bad[0]]}")


def describe(layout: Layout, index: int) -> str:
    """A readable name of entry ``index`` of w."""
    if index >= layout.parameter_start:
        return f"parameter {layout.parameters[index - layout.parameter_start]!r}"
    for pl in layout.phases:
        if pl.duration_index == index:
            return f"phase {pl.name!r} duration"
        if pl.midpoint_start <= index < pl.end:
            k, j = divmod(index - pl.midpoint_start, len(pl.states))
            return f"phase {pl.name!r} state {pl.states[j]!r} midpoint {k}"
        if pl.start <= index < pl.end:
            k, j = divmod(index - pl.start, pl.stride)
            if j < len(pl.states):
                return f"phase {pl.name!r} state {pl.states[j]!r} knot {k}"
            return f"phase {pl.name!r} control {pl.controls[j - len(pl.states)]!r} knot {k}"
    return f"w[{index}]"


def variable_bounds(problem: Problem, layout: Layout,
                    midpoint_bounds: bool = True) -> tuple[Array, Array]:
    """Default ``(lbw, ubw)`` from the statement: path bounds, then end-knot bounds on top.

    The midpoint states of the separated Hermite-Simpson form take the path state bounds when
    ``midpoint_bounds`` (the states then respect their bounds between knots too, and the
    dynamics are never evaluated far outside them during the iterations); without, they are
    unbounded like the compressed form's midpoints (which are no variables), and both forms
    have the same feasible set and optimum."""
    lbw, ubw = np.full(layout.size, -math.inf), np.full(layout.size, math.inf)
    for ph, pl in zip(problem.phases, layout.phases, strict=True):
        where = f"phase {ph.name!r}"
        for kind, path, first, last in (
                ("state", ph.state_bounds, ph.initial_state, ph.final_state),
                ("control", ph.control_bounds, ph.initial_control, ph.final_control)):
            for name, pb in path.items():
                lo, hi = as_bound(pb, f"{where} {kind} bound {name!r}")
                lbw[pl.across_knots(kind, name)], ubw[pl.across_knots(kind, name)] = lo, hi
                if kind == "state" and midpoint_bounds:
                    lbw[pl.across_midpoints(name)], ubw[pl.across_midpoints(name)] = lo, hi
            for knot, mapping, label in ((0, first, "initial"), (-1, last, "final")):
                for name, b in mapping.items():
                    i = pl.index(kind, name, knot)
                    lbw[i], ubw[i] = as_bound(b, f"{where} {label} {kind} {name!r}")
        if pl.duration_index is not None:
            spec = ph.duration_spec()
            lbw[pl.duration_index], ubw[pl.duration_index] = spec.lower, spec.upper
    for par in problem.parameters:
        i = layout.parameter(par.name)
        lbw[i], ubw[i] = par.lower, par.upper
    return lbw, ubw
