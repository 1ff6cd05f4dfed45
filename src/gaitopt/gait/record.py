"""Turning a solved walking problem into a :class:`~gaitopt.gait.gait_file.Gait` record.

Everything in the record is evaluated from the reduced solution with the same physics the
solver used (:mod:`gaitopt.gait.walking`), compiled once per model into small CasADi functions:
the full ``q, qd, qdd`` and the contact forces at every knot, the two events with their impulses
and velocities, and dense samples of the step on a uniform time grid with the transcription's
own interpolation (cubic Hermite states, linear controls).
"""

from __future__ import annotations

import functools
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.dynamics.backend import as_scalars
from gaitopt.dynamics.kinematics import point_position
from gaitopt.gait import cost, walking
from gaitopt.gait.accuracy import accuracy_record
from gaitopt.gait.formulation import contact_sequence
from gaitopt.gait.gait_file import Gait, GaitEvent, GaitPhase, GaitSamples
from gaitopt.gait.options import GaitOptions
from gaitopt.gait.record_costates import solution_costates
from gaitopt.gait.record_full import full_phases_and_events, full_samples
from gaitopt.gait.solve import WalkingSolution
from gaitopt.gait.transcriptions import disk_cached, function_file
from gaitopt.gait.walking import DOUBLE, SINGLE
from gaitopt.ocp import Result, warm_start_of
from gaitopt.robot.biped import reduced_biped
from gaitopt.robot.model import RobotModel

Array = NDArray[np.float64]

#: Samples per second of step time in the dense grid (at least 101 samples per step).
SAMPLE_RATE = 200.0


class MotionOutOfReachError(ValueError):
    """The solution's interpolated motion has no configuration at some sample time.

    The reach of the legs is enforced at the knots and midpoints of the grid only; between
    them the interpolated hip can pass beyond a leg's reach, where the leg's inverse
    kinematics has no solution. Such a solution is not a gait (it cannot be recorded or
    verified); a finer grid enforces the reach more densely."""


#: Version of the disk cache of ``_phase_functions`` (part of its key).
RECORD_FORMAT = "record-reduced-1"


@functools.lru_cache(maxsize=32)
def _phase_functions(model: RobotModel, phase: str, controls: tuple[str, ...]) -> ca.Function:
    """``(x, u, L) -> (q, qd, qdd, forces, u_full, xdot)`` for a phase, as one SX function,
    from the disk cache (keyed by the model, the phase, the controls, the gaitopt sources and
    CasADi's version) or built and saved there: building it (the Contact Algorithm in
    symbols) took 0.17 s of a whole 8 + 5 ``gaitopt solve`` for the two phases."""
    return disk_cached(function_file(RECORD_FORMAT, (model.content_hash(), phase, controls)),
                       lambda: _build_phase_functions(model, phase, controls))


def _build_phase_functions(model: RobotModel, phase: str, controls: tuple[str, ...]
                           ) -> ca.Function:
    n = len(walking.state_names(model, phase))
    x = ca.SX.sym("x", n)
    u = ca.SX.sym("u", len(controls))
    step = ca.SX.sym("L")
    if phase == SINGLE:
        point = walking.single_support_point(model, x, u, controls)
    else:
        point = walking.double_support_point(model, x, u, controls, step)
    sol = point.solution
    u_full = ca.vertcat(*walking.full_controls(model, controls, u))
    return ca.Function(f"record_{phase}", [x, u, step],
                       [sol.q, sol.qd, sol.qdd, sol.forces, u_full, point.xdot],
                       ["x", "u", "L"], ["q", "qd", "qdd", "forces", "u_full", "xdot"])


def sample_points(model: RobotModel) -> tuple[tuple[str, str, tuple[float, float]], ...]:
    """The named points of the gait samples: ``(name, link, point in the link frame)``.

    ``hip`` (the base origin), the origin of every link not attached to the base at its
    origin, named after its joint (``knee_1``, ``ankle_1``, ...), every contact point
    (``tip_1``, ``heel_1``, ...) and ``torso_top`` (the base link's far end), in that order.
    For the five-link biped: hip, knee_1, knee_2, tip_1, tip_2, torso_top."""
    base = model.base
    out = [("hip", base.name, (0.0, 0.0))]
    for link in model.links[1:]:
        if link.joint is None or (link.parent == base.name and
                                  tuple(link.joint.at) == (0.0, 0.0)):
            continue
        out.append((link.joint.name, link.name, (0.0, 0.0)))
    for c in model.contacts:
        x, y = model.link(c.link).local_point(*c.at)
        out.append((c.name, c.link, (float(x), float(y))))
    x, y = base.local_point(base.length)
    out.append(("torso_top", base.name, (float(x), float(y))))
    return tuple(out)


def point_names(model: RobotModel) -> tuple[str, ...]:
    """The names of :func:`sample_points`."""
    return tuple(name for name, _, _ in sample_points(model))


@functools.lru_cache(maxsize=8)
def _points_function(model: RobotModel) -> ca.Function:
    """``q -> (2, P)`` world positions of :func:`sample_points`."""
    q = ca.SX.sym("q", model.nq)
    cols = [point_position(model, q, link, p) for _, link, p in sample_points(model)]
    return ca.Function("record_points", [q], [ca.horzcat(*cols)])


def _evaluate(fn: ca.Function, x: Array, u: Array, step: float) -> list[Array]:
    out = fn.map(x.shape[0])(x.T, u.T, step)
    return [np.asarray(o, dtype=float).T for o in out]


def gait_from_solution(solution: WalkingSolution) -> Gait:
    """The gait record of a walking solution (converged or not: ``solver.success`` says).

    Raises:
        MotionOutOfReachError: the interpolated motion leaves a leg's reach between knots.
    """
    model, options, res = solution.model, solution.options, solution.result
    step, speed, impulse = (res.parameters[k] for k in ("step_length", "speed", "impulse"))
    # IPOPT may end a hair outside a bound (its bound_relax_factor): the impulse is >= 0.
    impulse = max(impulse, 0.0)
    traj = {ph.name: ph for ph in res.phases}
    if options.formulation == "full":
        total = sum(ph.duration for ph in res.phases)
        count = max(101, int(np.ceil(total * SAMPLE_RATE)) + 1)
        phase_records, events = full_phases_and_events(
            model, contact_sequence(model, options), res, step, impulse)
        samples = full_samples(model, res, count, _points_function(model),
                               point_names(model))
        return _gait(solution, phase_records, events, samples)
    legs = reduced_biped(model).legs
    lam = solution_costates(solution)
    phases: list[GaitPhase] = []
    for name in traj:
        ph = traj[name]
        contacts = (legs[0].contact,) if name == SINGLE else (legs[0].contact, legs[1].contact)
        fn = _phase_functions(model, name, tuple(ph.controls))
        q, qd, qdd, forces, u_full, _ = _evaluate(fn, ph.x, ph.u, step)
        phases.append(GaitPhase(
            name=name, contacts=contacts, t=ph.t, q=q, qd=qd, qdd=qdd, u=u_full,
            contact_forces={c: forces[:, 2 * i:2 * i + 2] for i, c in enumerate(contacts)},
            state_names=tuple(ph.states), x=ph.x, xdot=ph.xdot,
            error_estimate=ph.error if np.all(np.isfinite(ph.error)) else None,
            costates=lam.get(name)))
    events = _events(model, options, traj, step, impulse)
    samples = _samples(model, options, res, step)
    return _gait(solution, tuple(phases), events, samples)


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


def _vec(value: Any, n: int) -> Array:
    return np.array([float(v) for v in as_scalars(value, n, "value")])


def _events(model: RobotModel, options: GaitOptions, traj: dict[str, Any], step: float,
            impulse: float) -> tuple[GaitEvent, ...]:
    legs = reduced_biped(model).legs
    ss = traj[SINGLE]
    strike = walking.heel_strike(model, ss.x[-1], step, double_support=options.double_support)
    events = [GaitEvent(
        name="heel_strike", t=ss.tf, leg=legs[1].contact,
        impulses={c: _vec(v, 2) for c, v in strike.impulses.items()},
        qd_before=_vec(strike.qd_before, model.nq), qd_after=_vec(strike.qd_after, model.nq))]
    if options.double_support:
        ds = traj[DOUBLE]
        lift = walking.liftoff(model, ds.x[-1], step, impulse)
        events.append(GaitEvent(
            name="liftoff", t=ds.tf, leg=legs[0].contact,
            impulses={c: _vec(v, 2) for c, v in lift.impulses.items()},
            qd_before=_vec(lift.qd_before, model.nq), qd_after=_vec(lift.qd_after, model.nq)))
    else:
        after = _vec(strike.qd_after, model.nq)
        events.append(GaitEvent(name="liftoff", t=ss.tf, leg=legs[0].contact,
                                impulses={legs[0].contact: np.zeros(2)},
                                qd_before=after, qd_after=after))
    return tuple(events)


def _samples(model: RobotModel, options: GaitOptions, res: Any, step: float) -> GaitSamples:
    total = sum(ph.duration for ph in res.phases)
    t0 = res.phases[0].t0
    count = max(101, int(np.ceil(total * SAMPLE_RATE)) + 1)
    t = t0 + np.linspace(0.0, total, count)
    q = np.zeros((count, model.nq))
    qd = np.zeros((count, model.nq))
    u = np.zeros((count, model.nu))
    t_split = res.phases[0].tf
    for i, ph in enumerate(res.phases):
        mask = t <= t_split if i == 0 else t > t_split
        if not mask.any():
            continue
        x = ph.x_at(t[mask])
        uc = ph.u_at(t[mask])
        fn = _phase_functions(model, ph.name, tuple(ph.controls))
        q_s, qd_s, _, _, u_s, _ = _evaluate(fn, np.atleast_2d(x), np.atleast_2d(uc), step)
        bad = ~np.all(np.isfinite(q_s) & np.isfinite(qd_s), axis=1)
        if bad.any():
            times = t[mask][bad]
            raise MotionOutOfReachError(
                f"the solution's motion between knots leaves a leg's reach in phase "
                f"{ph.name} at {bad.sum()} of the {count} samples (t = {times[0]:.4f} to "
                f"{times[-1]:.4f} s): the reach is enforced at knots and midpoints only; "
                f"solve on a finer grid (more knots)")
        q[mask], qd[mask], u[mask] = q_s, qd_s, u_s
    names = point_names(model)
    pts = np.asarray(_points_function(model).map(count)(q.T), dtype=float)  # (2, P * count)
    pts = pts.T.reshape(count, len(names), 2)  # sample k, point j at row P k + j
    points = {name: pts[:, j, :] for j, name in enumerate(names)}
    return GaitSamples(t=t, q=q, qd=qd, u=u, points=points)
