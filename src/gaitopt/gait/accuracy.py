"""The accuracy of a walking solution: its collocation error and its cost's grid error.

Two figures, written to every gait file as ``solver.accuracy`` (``docs/outputs.md``):

* the collocation error per phase: the largest per-interval error estimate of the final grid,
  ``max_k max_j eta_kj / (1 + max_k |x_kj|)`` (:mod:`gaitopt.ocp.estimate`: the dynamics
  residual of the transcription's interpolant, integrated over the interval, relative to each
  state's size); dimensionless;
* the cost's discretization error estimate: the change of the cost from the previous grid the
  same problem was solved on, ``J(final grid) - J(previous grid)`` (N^2 m s), with both grids.
  The walking cost converges at about first order in the interval length (docs/walking.md,
  "Grid convergence"), so when the previous grid has about half the knots the change is about
  the final grid's remaining error ``J(final) - J(h -> 0)``; it is an estimate, not a bound.
  It is ``None`` when the solve ran on one grid only (a fixed grid equal to the coarse one, or
  a warm start): solve with ``mesh_tol`` to get one.
  The default solve (16 + 6 knots, torques free to jump) is compared with its 8 + 5 stage:
  at 12 m/min ``|J(16+6) - J(8+5)| = 3.28`` (0.76 % of J), while the 16 + 6 cost is within
  0.17 (0.04 %) of the 80 + 20 value; the estimate overstates the error there;
* how much the free parameters moved between the same two grids: ``speed_change`` (m/s) and
  ``step_length_change`` (m), ``final - previous`` (0 for a parameter held fixed), so the
  speed-free optimum says how settled its speed and step length are.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gaitopt.gait.solve import WalkingSolution

#: How the cost's discretization error is estimated (written to the gait file).
COST_ERROR_METHOD = "change of the cost from the previous grid: J(final) - J(previous)"


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def accuracy_record(solution: WalkingSolution) -> dict[str, Any]:
    """``solver.accuracy`` of a solution's gait file (plain JSON data).

    Keys: ``collocation_error`` (by phase name, the largest per-interval estimate, or null
    where not finite), ``knots`` (by phase name), ``mesh_tol`` (null: a fixed grid),
    ``mesh_converged`` (every estimate <= mesh_tol; null without mesh_tol), ``cost_error``
    (``J(final) - J(previous)``, N^2 m s, or null), ``cost_error_method``, ``previous_knots``
    (the previous grid's knots per phase, or null), ``previous_cost``,
    ``cost_error_relative`` (``|cost_error| / |J|``, or null), ``speed_change`` and
    ``step_length_change`` (final minus previous grid's value, m/s and m, or null).
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
        "cost_error_method": COST_ERROR_METHOD, "previous_knots": None, "previous_cost": None,
        "cost_error_relative": None, "speed_change": None, "step_length_change": None}
    final = tuple(knots.values())
    grids = solution.grid_costs
    if solution.success and grids and grids[-1][0] == final and \
            math.isclose(grids[-1][1], res.objective, rel_tol=1e-12, abs_tol=1e-12):
        earlier = [g for g in grids[:-1] if g[0] != final]
        if earlier:
            previous, cost = earlier[-1]
            out.update(cost_error=_finite(res.objective - cost), previous_cost=_finite(cost),
                       previous_knots=dict(zip(knots, previous, strict=True)))
            if res.objective != 0.0:
                out["cost_error_relative"] = _finite(abs(res.objective - cost)
                                                     / abs(res.objective))
            before = _parameters_of(solution, cost)
            if before is not None:
                for key, name in (("speed", "speed_change"),
                                  ("step_length", "step_length_change")):
                    if key in before and key in res.parameters:
                        out[name] = _finite(res.parameters[key] - before[key])
    return out


def _parameters_of(solution: WalkingSolution, cost: float) -> dict[str, float] | None:
    """The parameters of the last converged full-problem stage with objective ``cost`` (the
    previous grid's solution), or None."""
    for stage in reversed(solution.stages):
        if stage.full_problem and stage.success and stage.objective == cost:
            return dict(stage.parameters)
    return None
