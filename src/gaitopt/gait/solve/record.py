"""Turning a staged run (internal) into its :class:`~gaitopt.gait.record.file.Gait`, the one
public result of a solve.

The run's formulation extracts the phases, events and dense samples
(:meth:`gaitopt.gait.formulations.select.Formulation.record`:
:mod:`gaitopt.gait.formulations.reduced.extract`,
:mod:`gaitopt.gait.formulations.full.extract`); this module puts the parameters, the cost, the
solver's report and the contact sequence around them.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from gaitopt.gait.formulations import cost
from gaitopt.gait.formulations.record_points import SAMPLE_RATE as SAMPLE_RATE
from gaitopt.gait.formulations.record_points import point_names as point_names
from gaitopt.gait.formulations.record_points import sample_points as sample_points
from gaitopt.gait.formulations.reduced.extract import MotionOutOfReachError as MotionOutOfReachError
from gaitopt.gait.formulations.select import contact_sequence, formulation_of
from gaitopt.gait.record.file import Gait, GaitEvent, GaitPhase, GaitSamples
from gaitopt.gait.solve.accuracy import accuracy_record
from gaitopt.gait.solve.costates import solution_costates
from gaitopt.gait.solve.diagnose import diagnose
from gaitopt.gait.solve.staged import StagedRun
from gaitopt.gait.solve.staged_run import check_result
from gaitopt.ocp import Result, WarmStart, warm_start_of


def gait_from_run(run: StagedRun) -> Gait:
    """Returns the :class:`Gait` of a staged run, the one public result of a solve (converged
    or not: ``solver.success`` says). A failed run's gait carries its diagnosis
    (``solver.diagnosis``: :func:`gaitopt.gait.solve.diagnose.diagnose` as text).

    Raises:
        MotionOutOfReachError: the interpolated motion leaves a leg's reach between knots.
    """
    parts = formulation_of(run.options).record(run, lambda: solution_costates(run))
    return _gait(run, parts.phases, parts.events, parts.samples)


def _gait(run: StagedRun, phases: tuple[GaitPhase, ...],
          events: tuple[GaitEvent, ...], samples: GaitSamples) -> Gait:
    model, options, res = run.model, run.options, run.result
    step, speed = res.parameters["step_length"], res.parameters["speed"]
    impulse = max(res.parameters["impulse"], 0.0)
    t1 = res.phases[0].duration
    solver = {
        "status": res.status, "success": bool(res.success), "iterations": int(res.iterations),
        "wall_time_s": float(run.wall_time_s),
        "variables": res.nlp_size.variables,
        "equality_constraints": res.nlp_size.equality_constraints,
        "inequality_constraints": res.nlp_size.inequality_constraints,
        "evaluations": {k: int(v) for k, v in res.evaluations.items()},
        "max_violation": float(res.constraint_violation),
        "time_in_evaluations_s": float(res.times.get("evaluations", 0.0)),
        **({"warm_start": _warm_start_data(res)} if res.success else {}),
        **_check_point(run),
        "stages": [{"name": s.name, "knots": list(s.knots), "status": s.status,
                    "success": s.success, "iterations": s.iterations,
                    "objective": s.objective, "violation": s.violation,
                    "parameters": dict(s.parameters), "wall_time_s": s.wall_time_s}
                   for s in run.stages],
        "accuracy": {**accuracy_record(run), **(run.accuracy_extra or {})},
        **({} if run.share_release is None else {"phase_shares": dict(run.share_release)}),
        **({} if run.torque_rate_fallback is None else
           {"torque_rate_fallback": dict(run.torque_rate_fallback)}),
        **({} if res.success else {"diagnosis": diagnose(run).text()}),
    }
    gait = Gait(
        model_data=model.to_dict(), options=options.to_dict(),
        parameters={"step_length": step, "speed": speed, "step_time": step / speed,
                    "single_support_time": t1, "liftoff_impulse": impulse},
        cost={"value": float(res.objective), "name": options.cost,
              "formula": cost.formula(options)},
        solver=solver, phases=phases, events=events, samples=samples,
        contact_sequence=_solved_sequence(run))
    smoothing = cost.smoothing_record(gait) if res.success else None
    if smoothing is None:
        return gait
    return dataclasses.replace(gait, solver={
        **solver, "accuracy": {**solver["accuracy"], "smoothing": smoothing}})


def _warm_start_data(res: Result) -> dict[str, Any]:
    """What a warm start from the file needs (:class:`gaitopt.ocp.WarmStart`): the NLP point
    and its multipliers, with the layout and method they belong to."""
    return _point_data(warm_start_of(res))


def _point_data(point: WarmStart) -> dict[str, Any]:
    """A :class:`gaitopt.ocp.WarmStart` as plain JSON data."""
    return {"w": point.w.tolist(), "lam_x": point.lam_x.tolist(),
            "lam_g": point.lam_g.tolist(), "layout": point.layout, "method": point.method}


def _check_point(run: StagedRun) -> dict[str, Any]:
    """``{"warm_start_check": ...}``: the NLP point and multipliers of the answer's check grid
    (:func:`_warm_start_data`), where the run solved it and it converged to the cost the
    accuracy record names (``check_cost``), or the file's point whose estimate the run carries
    over (``StagedRun.carried_check``: no check grid solved); else nothing. A warm start
    from the file restarts its check grid there (:mod:`gaitopt.gait.solve.warm_accuracy`)."""
    if not run.success:
        return {}
    check = check_result(run)
    cost = accuracy_record(run).get("check_cost")
    if check is not None and cost is not None and check.objective == cost:
        return {"warm_start_check": _warm_start_data(check)}
    if check is None and run.carried_check is not None:
        return {"warm_start_check": _point_data(run.carried_check)}
    return {}


def _solved_sequence(run: StagedRun) -> dict[str, Any]:
    """The contact sequence of the run, with the phase fractions it solved (they are
    decision parameters when the single-support fraction is free)."""
    data = contact_sequence(run.model, run.options).to_dict()
    durations = [ph.duration for ph in run.result.phases]
    total = sum(durations)
    phases: list[dict[str, Any]] = list(data["phases"])
    for phase, duration in zip(phases, durations, strict=True):
        phase["fraction"] = float(duration / total)
    return data


