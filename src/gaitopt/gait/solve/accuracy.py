"""The accuracy of a walking solution: its collocation error and its cost's grid error.

Two figures, written to every gait file as ``solver.accuracy`` (``docs/outputs.md``):

* the collocation error per phase: the largest per-interval error estimate of the final grid,
  ``max_k max_j eta_kj / (1 + max_k |x_kj|)`` (:mod:`gaitopt.ocp.estimate`: the dynamics
  residual of the transcription's interpolant, integrated over the interval, relative to each
  state's size); dimensionless;
* an estimate of the cost's discretization error ``J(final) - J(limit)`` (N^2 m s), from the
  two grids of the solve, one of them the final grid:

  - a fixed-grid solve (``mesh_tol`` None, the default) solves its *check grid* after the
    answer (stage ``check grid``: 1.5 times the knots, the same spacing;
    :func:`gaitopt.gait.solve.check_grid.check_knots`, 24 + 8 for the default 16 + 6) and the
    estimate is the first-order error from the two, ``F (J(final) - J(check))`` with
    ``F = M / (M - N)`` (:func:`~gaitopt.gait.solve.check_grid.first_order_factor`: 3 from 16 to
    24 knots). Measured against cosine 120 + 30 knots at 12, 30 and 60 m/min with and
    without ankle torques, it bounds the true error at every point, by 1.1 to 2.7 times
    (docs/walking.md, section 6);
  - with ``mesh_tol`` the last round halves every interval and the estimate is the change
    from the mesh before, ``J(final) - J(previous)`` (factor 1);
  - a solve on one grid only (a warm start, the coarse grid itself, a failed check) has
    ``None``;

* how much the free parameters moved between the same two grids: ``speed_change`` (m/s) and
  ``step_length_change`` (m), the finer grid's value minus the coarser's (0 for a parameter
  held fixed), and their first-order estimates ``speed_error`` and ``step_length_error``
  (``F`` times the absolute change), so the speed-free optimum says how settled its speed
  and step length are.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gaitopt.gait.solve.check_grid import first_order_factor
from gaitopt.gait.solve.staged import StagedRun

#: How the cost's discretization error is estimated (written to the gait file), with a check
#: grid (``{factor}``: the first-order factor) and from the previous grid (``mesh_tol``).
CHECK_METHOD = ("first order from the check grid: {factor:g} (J(final) - J(check)), "
                "{factor:g} = M / (M - N) for N and M knots")
COST_ERROR_METHOD = "change of the cost from the previous grid: J(final) - J(previous)"


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def accuracy_record(solution: StagedRun) -> dict[str, Any]:
    """``solver.accuracy`` of a solution's gait file (plain JSON data).

    Keys: ``collocation_error`` (by phase name, the largest per-interval estimate, or null
    where not finite), ``knots`` (by phase name), ``mesh_tol`` (null: a fixed grid),
    ``mesh_converged`` (every estimate <= mesh_tol; null without mesh_tol), ``cost_error``
    (the estimate of ``J(final) - J(limit)``, N^2 m s, or null), ``cost_error_method``,
    ``cost_error_factor`` (``F``), ``check_knots`` and ``check_cost`` (the check grid's knots
    per phase and cost, or null), ``previous_knots`` and ``previous_cost`` (the last coarser
    grid's, or null), ``cost_error_relative`` (``|cost_error| / |J|``, or null),
    ``speed_change`` and ``step_length_change`` (finer minus coarser grid's value of the
    estimate's two grids, m/s and m, or null), ``speed_error`` and ``step_length_error``
    (``F`` times their absolute values, or null).
    """
    res = solution.result
    errors = {ph.name: _finite(float(np.max(ph.error))) if ph.error.size else 0.0
              for ph in res.phases}
    knots = {ph.name: int(ph.t.size) for ph in res.phases}
    tol = solution.options.mesh_tol
    finite = [e for e in errors.values() if e is not None]
    converged = None if tol is None else (len(finite) == len(errors) and max(finite) <= tol)
    out: dict[str, Any] = {
        "collocation_error": errors, "knots": knots, "mesh_tol": tol,
        "mesh_converged": converged, "cost_error": None,
        "cost_error_method": None, "cost_error_factor": None, "check_knots": None,
        "check_cost": None, "previous_knots": None, "previous_cost": None,
        "cost_error_relative": None, "speed_change": None, "step_length_change": None,
        "speed_error": None, "step_length_error": None}
    final = tuple(knots.values())
    grids = list(solution.grid_costs)
    at = next((i for i in reversed(range(len(grids))) if grids[i][0] == final and
               math.isclose(grids[i][1], res.objective, rel_tol=1e-12, abs_tol=1e-12)), None)
    if not solution.success or at is None:
        return out
    earlier = [g for g in grids[:at] if g[0] != final]
    if earlier:
        out.update(previous_cost=_finite(earlier[-1][1]),
                   previous_knots=dict(zip(knots, earlier[-1][0], strict=True)))
    check = next((g for g in grids[at + 1:] if g[0][0] > final[0]), None)
    if check is not None:
        factor = first_order_factor(final[0], check[0][0], of_finer=False)
        other, cost_error = check[1], factor * (res.objective - check[1])
        out.update(check_cost=_finite(other), check_knots=dict(zip(knots, check[0], strict=True)),
                   cost_error_method=CHECK_METHOD.format(factor=factor))
        sign = 1.0  # the check grid is the finer one
    elif earlier and tol is not None:
        factor, other = 1.0, earlier[-1][1]
        cost_error = res.objective - other
        out["cost_error_method"] = COST_ERROR_METHOD
        sign = -1.0  # the previous grid is the coarser one
    else:
        return out
    out.update(cost_error=_finite(cost_error), cost_error_factor=factor)
    if res.objective != 0.0:
        out["cost_error_relative"] = _finite(abs(cost_error) / abs(res.objective))
    before = _parameters_of(solution, other)
    if before is not None:
        for key in ("speed", "step_length"):
            if key in before and key in res.parameters:
                change = sign * (before[key] - res.parameters[key])
                out[f"{key}_change"] = _finite(change)
                out[f"{key}_error"] = _finite(factor * abs(change))
    return out


def _parameters_of(solution: StagedRun, cost: float) -> dict[str, float] | None:
    """The parameters of the last converged full-problem stage with objective ``cost`` (the
    previous grid's solution), or None."""
    for stage in reversed(solution.stages):
        if stage.full_problem and stage.success and stage.objective == cost:
            return dict(stage.parameters)
    return None
