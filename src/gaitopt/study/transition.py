"""The walk-run transition speed from two cost curves on a speed grid (numbers only).

At each speed ``v_i`` of a grid, the cheapest walk costs ``W_i`` and the run ``R_i`` (the
same cost, e.g. the paper's ``int u'u dt / L`` in N^2 m s, or a cost of transport), each with
its grid error estimate ``e`` (``solver.accuracy.cost_error`` of the gait file: the estimate
of ``J(grid) - J(limit)``, the same unit; NaN when unknown). A point that failed has no cost
(NaN) and plays no part: the transition is computed on the speeds where both converged.

With ``D_i = R_i - W_i`` (positive: the walk is cheaper), the transition is the last pair of
consecutive speeds of that set with ``D_i > 0 >= D_{i+1}`` (the walk cheaper, then the run;
the last, so that a run cheaper at one low speed between walks, within the grid errors of
two nearly equal costs, is not taken for the transition; :attr:`Transition.changes` counts
every change of the cheaper gait):

* the *bracket* ``[v_i, v_{i+1}]``;
* the *crossing* of the two cost curves, each linear between the grid speeds::

      v* = v_i + (v_{i+1} - v_i) D_i / (D_i - D_{i+1})

* its *grid-error interval*: the crossing with every ``D`` moved by the grid error of both
  costs, ``D_j +- (|e_Rj| + |e_Wj|)`` (the largest shift each way; ``D`` falls across the
  bracket, so raising it moves the crossing up). Where the shift removes the sign change
  the interval reaches the bracket's end and :attr:`Transition.leaves_bracket` says so. An
  unknown estimate (NaN) counts as 0 and :attr:`Transition.unknown_errors` counts them.

The cases without such a pair: ``walk`` (the walk is cheaper at every common speed: the
transition, if any, lies above the grid), ``run`` (the run is cheaper or equal at every
common speed: it lies at or below the lowest), ``run-to-walk`` (the run is cheaper at low
and the walk at high speed, the opposite of Srinivasan and Ruina's order), ``none`` (fewer
than two common speeds and no verdict). A crossing at the grid's end is an ordinary bracket
(the first or the last interval); ``D_i = 0`` at a speed puts the crossing on it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

#: People's walk-run transition: about 2 m/s (120 m/min; reported 1.9-2.2 m/s) at a Froude
#: number ``v^2 / (g l)`` of about 0.5 (Alexander 1989; Hreljac 1993; Kram, Domingo and Ferris
#: 1997 find 0.5 with legs of 0.9 m).
HUMAN_TRANSITION_SPEED = 2.0
HUMAN_TRANSITION_FROUDE = 0.5
#: How near to people's Froude number a model's transition counts as "near" in the findings:
#: within this band (0.35-0.65, people's 1.8-2.4 m/s on 0.93 m legs).
HUMAN_FROUDE_BAND = (0.35, 0.65)

TransitionKind = Literal["crossing", "walk", "run", "run-to-walk", "none"]


@dataclass(frozen=True)
class Transition:
    """The walk-run transition of two cost curves (module docstring). Speeds in m/s.

    ``kind``: ``crossing`` (a walk-to-run bracket), ``walk``, ``run``, ``run-to-walk`` or
    ``none``; ``bracket`` the two grid speeds around the crossing, ``speed`` the interpolated
    crossing and ``interval`` its grid-error interval (all NaN without a crossing);
    ``speeds`` the speeds where both converged (the others are ``skipped``, failed on one
    branch or both); ``changes`` how many times the cheaper gait changes along ``speeds``
    (1 for one clean transition); ``leaves_bracket``: the grid error could remove the sign
    change (the interval is clipped to the bracket); ``unknown_errors``: estimates missing
    (NaN, counted as 0) at the bracket's two speeds.
    """

    kind: TransitionKind
    bracket: tuple[float, float]
    speed: float
    interval: tuple[float, float]
    speeds: tuple[float, ...]
    skipped: tuple[float, ...]
    changes: int
    leaves_bracket: bool = False
    unknown_errors: int = 0

    @property
    def uncertainty(self) -> float:
        """Half the width of :attr:`interval` (m/s): the crossing is ``speed +- this`` from
        the grid error alone; NaN without a crossing."""
        lo, hi = self.interval
        return 0.5 * (hi - lo)


def crossing(v0: float, v1: float, d0: float, d1: float) -> float:
    """The zero of the line through ``(v0, d0)`` and ``(v1, d1)``, clipped to ``[v0, v1]``
    (``d0 = d1``: the midpoint)."""
    if d0 == d1:
        return 0.5 * (v0 + v1)
    v = v0 + (v1 - v0) * d0 / (d0 - d1)
    return min(max(v, v0), v1)


def _abs_or_zero(x: float) -> tuple[float, int]:
    return (0.0, 1) if not math.isfinite(x) else (abs(x), 0)


def walk_run_transition(speeds: Sequence[float], walk: Sequence[float],
                        run: Sequence[float], *,
                        walk_error: Sequence[float] | None = None,
                        run_error: Sequence[float] | None = None) -> Transition:
    """The transition of the cost curves ``walk`` and ``run`` (the cheapest walk and the run
    at each of ``speeds``, m/s, ascending; NaN where a solve failed), with their grid error
    estimates (None: unknown everywhere). See the module docstring.

    Raises:
        ValueError: sequences of different lengths, or speeds not strictly ascending.
    """
    n = len(speeds)
    we = list(walk_error) if walk_error is not None else [math.nan] * n
    re_ = list(run_error) if run_error is not None else [math.nan] * n
    if not (len(walk) == len(run) == len(we) == len(re_) == n):
        raise ValueError(f"walk_run_transition: {n} speeds, {len(walk)} walk costs, {len(run)} "
                         f"run costs, {len(we)} and {len(re_)} error estimates: one per speed")
    if any(b <= a for a, b in zip(speeds, speeds[1:], strict=False)):
        raise ValueError("walk_run_transition: speeds must be strictly ascending")
    both = [i for i in range(n) if math.isfinite(walk[i]) and math.isfinite(run[i])]
    common = tuple(float(speeds[i]) for i in both)
    skipped = tuple(float(speeds[i]) for i in range(n) if i not in both)
    nan2 = (math.nan, math.nan)
    if len(both) < 2:
        return Transition("none", nan2, math.nan, nan2, common, skipped, 0)
    d = [run[i] - walk[i] for i in both]
    walk_cheaper = [x > 0 for x in d]
    changes = sum(a != b for a, b in zip(walk_cheaper, walk_cheaper[1:], strict=False))
    first = next((k for k in reversed(range(len(d) - 1)) if d[k] > 0 >= d[k + 1]), None)
    if first is None:
        kind: TransitionKind = ("walk" if all(walk_cheaper) else
                                "run" if not any(walk_cheaper) else "run-to-walk")
        return Transition(kind, nan2, math.nan, nan2, common, skipped, changes)
    i, j = both[first], both[first + 1]
    v0, v1 = float(speeds[i]), float(speeds[j])
    (ew0, u0), (er0, u1) = _abs_or_zero(we[i]), _abs_or_zero(re_[i])
    (ew1, u2), (er1, u3) = _abs_or_zero(we[j]), _abs_or_zero(re_[j])
    e0, e1 = ew0 + er0, ew1 + er1
    d0, d1 = d[first], d[first + 1]
    lo_d0, lo_d1, hi_d0, hi_d1 = d0 - e0, d1 - e1, d0 + e0, d1 + e1
    leaves = not (lo_d0 > 0 >= lo_d1 and hi_d0 > 0 >= hi_d1)
    lo = v0 if lo_d0 <= 0 else crossing(v0, v1, lo_d0, lo_d1) if lo_d1 <= 0 else v1
    hi = v1 if hi_d1 > 0 else crossing(v0, v1, hi_d0, hi_d1) if hi_d0 > 0 else v0
    return Transition("crossing", (v0, v1), crossing(v0, v1, d0, d1), (min(lo, hi), max(lo, hi)),
                      common, skipped, changes, leaves_bracket=leaves,
                      unknown_errors=u0 + u1 + u2 + u3)


def froude_number(speed: float, leg_length: float, gravity: float = 9.81) -> float:
    """``Fr = v^2 / (g l)`` (dimensionless) of ``speed`` (m/s) on legs of ``leg_length`` (m)."""
    return speed * speed / (gravity * leg_length)
