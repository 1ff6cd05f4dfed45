"""The checks of a whole gait record: its solver record and the consistency of its phases,
events and samples with its model and with each other (shapes, contact names, times), and the
reading of its model. :class:`~gaitopt.gait.record.file.Gait` runs them when it is built.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from gaitopt.gait.record.fields import bad_field, mapping_of, number_of
from gaitopt.gait.record.parts import GaitEvent, GaitPhase, GaitSamples
from gaitopt.robot import RobotModel, model_from_dict

SOLVER_KEYS: tuple[str, ...] = ("status", "success", "iterations", "wall_time_s", "variables",
                                "equality_constraints", "inequality_constraints", "evaluations",
                                "max_violation")


def parse_model(data: Any) -> RobotModel:
    """The model of a gait's ``model`` field (model-file schema).

    A link giving both ``inertia`` and ``shape`` is read by its explicit inertia (older
    loaders wrote both but accepted only one).
    """
    if isinstance(data, Mapping) and isinstance(data.get("links"), list):
        data = dict(data)
        data["links"] = [
            {k: v for k, v in link.items() if k != "shape"}
            if isinstance(link, Mapping) and "inertia" in link and "shape" in link else link
            for link in data["links"]]
    return model_from_dict(data, source="model")


#: The numbers of ``solver.accuracy.smoothing``
#: (:func:`gaitopt.gait.formulations.cost.smoothing_record`).
SMOOTHING_KEYS = ("cost_smoothing", "unsmoothed_cost", "share")


def check_solver(value: Any) -> dict[str, Any]:
    """Returns a checked copy of a gait's ``solver`` record (:data:`SOLVER_KEYS` present and
    typed, an optional ``diagnosis`` a string); raises :class:`GaitFileError` naming the field."""
    solver = mapping_of("solver", value, required=SOLVER_KEYS)
    if not isinstance(solver["status"], str):
        raise bad_field("solver.status", "expected a string")
    if isinstance(solver["success"], np.bool_):
        solver["success"] = bool(solver["success"])
    if not isinstance(solver["success"], bool):
        raise bad_field("solver.success", f"expected true or false, got {solver['success']!r}")
    for key in ("iterations", "variables", "equality_constraints", "inequality_constraints"):
        v = solver[key]
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 0:
            raise bad_field(f"solver.{key}", f"expected an integer >= 0, got {v!r}")
        solver[key] = int(v)
    for key in ("wall_time_s", "max_violation"):
        solver[key] = number_of(f"solver.{key}", solver[key], minimum=0.0)
    evaluations = mapping_of("solver.evaluations", solver["evaluations"])
    for kind, count in evaluations.items():
        if isinstance(count, bool) or not isinstance(count, int | np.integer) or count < 0:
            raise bad_field(f"solver.evaluations.{kind}",
                            f"expected an integer >= 0, got {count!r}")
    solver["evaluations"] = {str(k): int(v) for k, v in evaluations.items()}
    if "verify" in solver:  # the solve's own run of verify's checks (gaitopt solve)
        record = mapping_of("solver.verify", solver["verify"], required=("passed", "failed"))
        if not isinstance(record["passed"], bool) or not isinstance(record["failed"], list):
            raise bad_field("solver.verify", "expected passed (true or false) and failed (a "
                            "list of the failed checks)")
    accuracy = solver.get("accuracy")
    if isinstance(accuracy, Mapping) and "smoothing" in accuracy:  # a cost of transport's
        smoothing = mapping_of("solver.accuracy.smoothing", accuracy["smoothing"],
                               required=SMOOTHING_KEYS)
        solver["accuracy"] = {**accuracy, "smoothing": {
            key: number_of(f"solver.accuracy.smoothing.{key}", smoothing[key])
            for key in SMOOTHING_KEYS}}
    if "diagnosis" in solver and not isinstance(solver["diagnosis"], str):
        raise bad_field("solver.diagnosis", "expected a string (the diagnosis of a failed "
                        "solve)")
    return solver


def check_consistency(model: RobotModel, p: Mapping[str, float], phases: Sequence[Any],
                      events: Sequence[Any], s: Any, steps: int = 1) -> None:
    """The parts of a gait agree with its ``model`` (``nq``, ``nu``, contact names) and with
    each other: parameters ``p`` (checked numbers) against the phases' span (``steps`` step
    times: 2 for a stride), phases joined in time, events and samples inside the period.
    Raises :class:`~gaitopt.gait.record.fields.GaitFileError` naming the field.
    """
    nq, nu = model.nq, model.nu
    contacts = [c.name for c in model.contacts]
    if p["step_time"] <= 0.0:
        raise bad_field("parameters.step_time", f"expected > 0, got {p['step_time']:g}")
    if p["single_support_time"] > p["step_time"] * (1 + 1e-9):
        raise bad_field("parameters.single_support_time",
                        f"{p['single_support_time']:g} s exceeds the step time "
                        f"{p['step_time']:g} s")
    if not phases:
        raise bad_field("phases", "expected at least one phase")
    for i, phase in enumerate(phases):
        where = f"phases[{i}]"
        if not isinstance(phase, GaitPhase):
            raise bad_field(where, f"expected a GaitPhase, got {type(phase).__name__}")
        if phase.q.shape[1] != nq or phase.u.shape[1] != nu:
            raise bad_field(f"{where}.q", f"the model has nq={nq}, nu={nu}; the phase has "
                            f"q with {phase.q.shape[1]} and u with {phase.u.shape[1]} columns")
        for c in phase.contacts:
            if c not in contacts:
                raise bad_field(f"{where}.contacts", f"{c!r} is not a contact of the model "
                                f"({', '.join(contacts)})")
        if i > 0 and not math.isclose(phase.t[0], phases[i - 1].t[-1], abs_tol=1e-9):
            raise bad_field(f"{where}.t", f"starts at {phase.t[0]:g} s but the previous phase ends "
                            f"at {phases[i - 1].t[-1]:g} s")
    span = phases[-1].t[-1] - phases[0].t[0]
    if not math.isclose(span, steps * p["step_time"], rel_tol=1e-6, abs_tol=1e-9):
        times = "" if steps == 1 else f" x {steps} steps (a stride)"
        raise bad_field("parameters.step_time", f"{p['step_time']:g} s{times} differs from the "
                        f"phases' span {span:g} s")
    t0, t1 = phases[0].t[0] - 1e-9, phases[-1].t[-1] + 1e-9
    for i, event in enumerate(events):
        where = f"events[{i}]"
        if not isinstance(event, GaitEvent):
            raise bad_field(where, f"expected a GaitEvent, got {type(event).__name__}")
        if event.leg not in contacts:
            raise bad_field(f"{where}.leg", f"{event.leg!r} is not a contact of the model")
        if not t0 <= event.t <= t1:
            raise bad_field(f"{where}.t", f"{event.t:g} s is outside the step [{t0:g}, {t1:g}] s")
        if event.qd_before.size != nq:
            raise bad_field(f"{where}.qd_before", f"expected {nq} entries (nq)")
        for c in event.impulses:
            if c not in contacts:
                raise bad_field(f"{where}.impulses", f"{c!r} is not a contact of the model")
    if not isinstance(s, GaitSamples):
        raise bad_field("samples", f"expected GaitSamples, got {type(s).__name__}")
    if s.q.shape[1] != nq or s.u.shape[1] != nu:
        raise bad_field("samples.q", f"the model has nq={nq}, nu={nu}; the samples have "
                        f"{s.q.shape[1]} and {s.u.shape[1]} columns")
    if s.t[0] < t0 or s.t[-1] > t1:
        raise bad_field("samples.t", f"[{s.t[0]:g}, {s.t[-1]:g}] s is outside the step")
