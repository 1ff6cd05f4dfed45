"""Turning a solved walking problem into a :class:`~gaitopt.gait.gait_file.Gait` record.

The solution's formulation extracts the phases, events and dense samples
(:meth:`gaitopt.gait.formulation.Formulation.record`: :mod:`gaitopt.gait.record_reduced`,
:mod:`gaitopt.gait.record_full`); this module puts the parameters, the cost, the solver's
report and the contact sequence around them.
"""

from __future__ import annotations

from typing import Any

from gaitopt.gait import cost
from gaitopt.gait.accuracy import accuracy_record
from gaitopt.gait.formulation import contact_sequence, formulation_of
from gaitopt.gait.gait_file import Gait, GaitEvent, GaitPhase, GaitSamples
from gaitopt.gait.record_costates import solution_costates
from gaitopt.gait.record_points import SAMPLE_RATE as SAMPLE_RATE
from gaitopt.gait.record_points import point_names as point_names
from gaitopt.gait.record_points import sample_points as sample_points
from gaitopt.gait.record_reduced import MotionOutOfReachError as MotionOutOfReachError
from gaitopt.gait.solve import WalkingSolution
from gaitopt.ocp import Result, warm_start_of


def gait_from_solution(solution: WalkingSolution) -> Gait:
    """The gait record of a walking solution (converged or not: ``solver.success`` says).

    Raises:
        MotionOutOfReachError: the interpolated motion leaves a leg's reach between knots.
    """
    parts = formulation_of(solution.options).record(
        solution, lambda: solution_costates(solution))
    return _gait(solution, parts.phases, parts.events, parts.samples)


def _gait(solution: WalkingSolution, phases: tuple[GaitPhase, ...],
          events: tuple[GaitEvent, ...], samples: GaitSamples) -> Gait:
    model, options, res = solution.model, solution.options, solution.result
    step, speed = res.parameters["step_length"], res.parameters["speed"]
    impulse = max(res.parameters["impulse"], 0.0)
    t1 = res.phases[0].duration
    solver = {
        "status": res.status, "success": bool(res.success), "iterations": int(res.iterations),
        "wall_time_s": float(solution.wall_time_s),
        "variables": res.nlp_size.variables,
        "equality_constraints": res.nlp_size.equality_constraints,
        "inequality_constraints": res.nlp_size.inequality_constraints,
        "evaluations": {k: int(v) for k, v in res.evaluations.items()},
        "max_violation": float(res.constraint_violation),
        "time_in_evaluations_s": float(res.times.get("evaluations", 0.0)),
        **({"warm_start": _warm_start_data(res)} if res.success else {}),
        "stages": [{"name": s.name, "knots": list(s.knots), "status": s.status,
                    "success": s.success, "iterations": s.iterations,
                    "objective": s.objective, "wall_time_s": s.wall_time_s}
                   for s in solution.stages],
        "accuracy": {**accuracy_record(solution), **(solution.accuracy_extra or {})},
    }
    return Gait(
        model_data=model.to_dict(), options=options.to_dict(),
        parameters={"step_length": step, "speed": speed, "step_time": step / speed,
                    "single_support_time": t1, "liftoff_impulse": impulse},
        cost={"value": float(res.objective), "name": options.cost,
              "formula": cost.formula(options)},
        solver=solver, phases=phases, events=events, samples=samples,
        contact_sequence=_solved_sequence(solution))


def _warm_start_data(res: Result) -> dict[str, Any]:
    """What a warm start from the file needs (:class:`gaitopt.ocp.WarmStart`): the NLP point
    and its multipliers, with the layout and method they belong to."""
    point = warm_start_of(res)
    return {"w": point.w.tolist(), "lam_x": point.lam_x.tolist(),
            "lam_g": point.lam_g.tolist(), "layout": point.layout, "method": point.method}


def _solved_sequence(solution: WalkingSolution) -> dict[str, Any]:
    """The contact sequence of the solution, with the phase fractions it solved (they are
    decision parameters when the single-support fraction is free)."""
    data = contact_sequence(solution.model, solution.options).to_dict()
    durations = [ph.duration for ph in solution.result.phases]
    total = sum(durations)
    phases: list[dict[str, Any]] = list(data["phases"])
    for phase, duration in zip(phases, durations, strict=True):
        phase["fraction"] = float(duration / total)
    return data


