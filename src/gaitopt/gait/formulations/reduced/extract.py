"""The record of a solve in the paper's reduced coordinates: its phases, events and samples.

Everything is evaluated from the reduced solution with the same physics the solver used
(:mod:`gaitopt.gait.formulations.reduced.physics`), compiled once per model into small CasADi
functions: the full ``q, qd, qdd`` and the contact forces at every knot, the two events with their
impulses and velocities, and dense samples of the step on a uniform time grid with the
transcription's own interpolation (cubic Hermite states, linear controls).
:mod:`gaitopt.gait.solve.record` assembles the :class:`~gaitopt.gait.record.file.Gait` around them.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.dynamics.backend import as_scalars
from gaitopt.dynamics.function_cache import disk_cached, function_file
from gaitopt.gait.formulations.record_points import (
    SAMPLE_RATE,
    RecordParts,
    point_names,
    points_function,
)
from gaitopt.gait.formulations.reduced import physics as walking
from gaitopt.gait.formulations.reduced.physics import DOUBLE, SINGLE
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import GaitEvent, GaitPhase, GaitSamples
from gaitopt.gait.solve.staged_run import StagedRun
from gaitopt.robot.biped import reduced_biped
from gaitopt.robot.model import RobotModel

Array = NDArray[np.float64]


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


def _evaluate(fn: ca.Function, x: Array, u: Array, step: float) -> list[Array]:
    out = fn.map(x.shape[0])(x.T, u.T, step)
    return [np.asarray(o, dtype=float).T for o in out]


def reduced_record(solution: StagedRun, costates: Callable[[], Mapping[str, Array]]
                   ) -> RecordParts:
    """The phases, events and samples of a reduced-coordinate solution; ``costates`` gives
    the costates of its phases (:func:`gaitopt.gait.solve.costates.solution_costates`).

    Raises:
        MotionOutOfReachError: the interpolated motion leaves a leg's reach between knots.
    """
    model, options, res = solution.model, solution.options, solution.result
    step, impulse = res.parameters["step_length"], res.parameters["impulse"]
    # IPOPT may end a hair outside a bound (its bound_relax_factor): the impulse is >= 0.
    impulse = max(impulse, 0.0)
    traj = {ph.name: ph for ph in res.phases}
    legs = reduced_biped(model).legs
    lam = costates()
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
    return RecordParts(tuple(phases), events, samples)


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
    pts = np.asarray(points_function(model).map(count)(q.T), dtype=float)  # (2, P * count)
    pts = pts.T.reshape(count, len(names), 2)  # sample k, point j at row P k + j
    points = {name: pts[:, j, :] for j, name in enumerate(names)}
    return GaitSamples(t=t, q=q, qd=qd, u=u, points=points)
