"""A solve that refines itself until its estimates are within ``GaitOptions.accuracy``.

A fixed-grid solve estimates its own grid error from its check grid
(:mod:`gaitopt.gait.solve.accuracy`: the cost's, and how far the speed and step length moved). The
relative estimates are

* cost: ``|cost_error| / |J|``;
* speed: ``speed_error / speed`` (0 where the speed is given);
* step length: ``step_length_error / step_length`` (0 where it is given).

While the largest exceeds ``accuracy`` (and the caller left the knots to the model's default),
the gait is solved again on its check grid (:func:`gaitopt.gait.solve.check_grid.check_knots`: 1.5
times the knots), started from the previous grid's gait, whose own check grid then gives the
next estimate; at most :data:`MAX_ROUNDS` times (16 + 6 -> 24 + 8 -> 36 + 12 -> 54 + 18 on the
five-link walk), and no more once the cost's estimate is above the target and larger than
the grid's before (``accuracy.diverging``, :func:`refine_to_accuracy`). Where the phases'
shares of the step are free, each finer grid's knots per phase follow the shares the previous
grid solved for (``GaitOptions.phase_shares``, :func:`solved_shares`; the density rule of
:func:`gaitopt.gait.sequence.contact_sequence.phase_knots`): a run's flight that grew to 65 %
of the step after a stance of 35 % gets 1 + 28 knots on 16 + 6, not 6. The answer is the
finest converged grid's gait, with ``accuracy.target``, ``accuracy.within_target`` and
``accuracy.refinements`` in its file; the command line exits with status 3 when it is not
within the target, and ``gaitopt verify`` fails its check ``accuracy.estimate``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any

from gaitopt.gait.formulations.select import contact_sequence
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.sequence.phase_fractions import free_phases
from gaitopt.gait.solve.check_grid import check_knots
from gaitopt.gait.solve.share_release import shares_of
from gaitopt.gait.solve.staged_run import StagedRun

#: How many times a solve is repeated on a finer grid at most.
MAX_ROUNDS = 3


def relative_estimates(accuracy: Mapping[str, Any],
                       parameters: Mapping[str, float]) -> dict[str, float | None]:
    """The relative error estimates of a gait file's ``solver.accuracy`` (module docstring):
    ``{"cost": ..., "speed": ..., "step_length": ...}``, each ``None`` where the solve has no
    estimate (a single grid, a failed check grid)."""
    out: dict[str, float | None] = {"cost": accuracy.get("cost_error_relative")}
    for key in ("speed", "step_length"):
        err, value = accuracy.get(f"{key}_error"), parameters.get(key)
        out[key] = (None if err is None or value is None or value == 0.0
                    else abs(float(err)) / abs(float(value)))
    return out


def worst_estimate(accuracy: Mapping[str, Any],
                   parameters: Mapping[str, float]) -> tuple[float, str]:
    """The largest relative estimate and its name (``inf`` and ``"cost"`` without one)."""
    rel = relative_estimates(accuracy, parameters)
    if rel["cost"] is None:
        return math.inf, "cost"
    name = max((k for k in rel if rel[k] is not None), key=lambda k: rel[k] or 0.0)
    value = rel[name]
    return (math.inf if value is None else float(value)), name


def describe(worst: tuple[float, str], target: float) -> str:
    """E.g. ``cost estimate 1.8 % > 1 %``."""
    value, name = worst
    shown = "none" if not math.isfinite(value) else f"{100 * value:.2g} %"
    op = "<=" if value <= target else ">"
    return f"{name.replace('_', ' ')} estimate {shown} {op} {100 * target:g} %"


def diverging_text(accuracy: Mapping[str, Any]) -> str:
    """E.g. ``; stopped: the cost estimate grew from 0.74 % to 1.9 % ...`` for a
    ``solver.accuracy`` record whose refinement stopped early (``diverging``), else ``""``."""
    history = [e for e in accuracy.get("cost_estimates") or () if e is not None]
    if not accuracy.get("diverging") or len(history) < 2:
        return ""
    return (f"; stopped: the cost estimate grew from {100 * history[-2]:.2g} % to "
            f"{100 * history[-1]:.2g} % (the grids do not converge: another local optimum?)")


def solved_shares(solution: StagedRun) -> tuple[float, ...] | None:
    """Each phase's share of the step in ``solution`` (its duration over the step time),
    where the contact sequence leaves some share free; else None."""
    seq = contact_sequence(solution.model, solution.options)
    if not free_phases(seq) or len(solution.result.phases) != len(seq.phases):
        return None
    return tuple(shares_of(solution))


def refine_to_accuracy(solution: StagedRun, *, refines: bool,
                       solve_on: Callable[[GaitOptions, StagedRun], StagedRun],
                       accuracy_of: Callable[[StagedRun], dict[str, Any]],
                       max_rounds: int = MAX_ROUNDS,
                       ) -> tuple[StagedRun, dict[str, Any]]:
    """Refine ``solution`` while its worst relative estimate exceeds the options' accuracy.

    Args:
        solution: the first solve.
        refines: whether refinement applies (an accuracy is set and the knots were not given).
        solve_on: solves ``options`` (a finer grid) started from the previous solution.
        accuracy_of: the ``solver.accuracy`` record of a solution
            (:func:`gaitopt.gait.solve.accuracy.accuracy_record`).
        max_rounds: the most refinements (:data:`MAX_ROUNDS` unless a caller asks for more:
            the cost study's accuracy pass).

    The loop also stops when the cost's relative estimate is above the target and larger
    than the grid's before (``diverging``). On grids in their asymptotic range the
    first-order estimate shrinks by about 1/1.5 from one grid to the next; the cost's that
    grows says the grids do not converge, typically because the finer grid's solve reached
    another local optimum, and a finer grid (3.4 times the work of the last: 1.5 times the
    knots, solved and checked) is not expected to help. Only the cost's: a flat optimum's
    speed or step length may move more on one grid than on the coarser one and settle on the
    next (the five-link walk at 30 m/min without ankle torques: step-length estimates 5.0,
    0.80, 1.2 and 0.14 %, its cost's 1.6, 0.72, 0.32, 0.13 %), and only above the target: a
    cost estimate far within it may grow by noise while the step length's settles (the
    seven-link run at 150 m/min: 0.11 then 0.14 %, its step length's 1.7 % the worst).
    Measured on the seven-link's metabolic walk at 4.8 W/kg (docs/costs.md, "Refinement that
    does not converge").

    Returns:
        The finest converged solution and what to add to its ``solver.accuracy``: ``target``
        (the accuracy, or None where refinement does not apply), ``within_target`` (bool, or
        None without a target), ``refinements`` (rounds solved), ``worst_estimate``
        (relative, or None), ``worst_estimate_of`` (its name), ``cost_estimates`` (the
        cost's relative estimate of each grid solved, coarsest first; None for a grid without
        one; the list None without a target) and ``diverging`` (True when the loop stopped
        because the cost's estimate grew; None without a target).
    """
    target = solution.options.accuracy if refines else None
    rounds = 0
    cost_estimates: list[float | None] = []
    while True:
        record = accuracy_of(solution)
        params = dict(solution.result.parameters)
        worst = worst_estimate(record, params)
        within = worst[0] <= target if target is not None else None
        cost = relative_estimates(record, params)["cost"]
        cost = cost if cost is not None and math.isfinite(cost) else None
        before = cost_estimates[-1] if cost_estimates else None
        # only a cost estimate above the target (a small one that grew, with the step's the
        # worst, is refined on: the seven-link run at 150 m/min, 0.11 then 0.14 %, step
        # 1.7 %); a grid without an estimate (its check failed) is refined on
        diverging = (target is not None and cost is not None and cost > target
                     and before is not None and cost > before)
        cost_estimates.append(cost)
        if (within is not False or rounds >= max_rounds or not solution.success
                or diverging):
            break
        finer = solution.options.replace(knots=check_knots(solution.options.knots),
                                         phase_shares=solved_shares(solution))
        again = solve_on(finer, solution)
        if not again.success:
            break
        solution, rounds = again, rounds + 1
    extra = {"target": target, "within_target": within, "refinements": rounds,
             "worst_estimate": worst[0] if math.isfinite(worst[0]) else None,
             "worst_estimate_of": worst[1],
             "cost_estimates": cost_estimates if refines else None,
             "diverging": diverging if refines else None}
    return dataclasses.replace(solution, accuracy_extra=extra), extra
