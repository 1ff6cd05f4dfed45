"""The gait record of a full-coordinate solution (:mod:`gaitopt.gait.formulations.full.problem`).

The phase states are ``x = [q, qd]`` themselves, so ``q, qd`` at the knots and in the dense
samples are read off the states and their cubic Hermite interpolant (no inverse kinematics:
no motion between knots can leave a leg's reach). ``qdd`` and the contact forces at the knots
are the Contact Algorithm's at the knot's state and torques (the physical accelerations: the
projection controls, which vanish with the grid, are not part of them); the events are the
event maps of the contact sequence applied to the end states.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.dynamics.backend import as_scalars
from gaitopt.dynamics.function_cache import disk_cached, function_file
from gaitopt.dynamics.tree import hold_name
from gaitopt.gait.formulations.full import physics as full
from gaitopt.gait.formulations.record_points import (
    SAMPLE_RATE,
    RecordParts,
    point_names,
    points_function,
)
from gaitopt.gait.record.file import GaitEvent, GaitPhase, GaitSamples
from gaitopt.gait.sequence.contact_sequence import ContactSequence
from gaitopt.gait.solve.staged_run import StagedRun
from gaitopt.robot.model import RobotModel

Array = NDArray[np.float64]


#: Version of the disk cache of ``_phase_function`` (part of its key).
RECORD_FORMAT = "record-full-1"


def phase_function_file(model: RobotModel, held: tuple[str, ...], actuators: tuple[str, ...]
                        ) -> Path:
    """Where ``_phase_function`` of a phase is cached on disk: keyed by the model, the
    held points, the actuators, the gaitopt sources and CasADi's version
    (:func:`gaitopt.gait.solve.transcriptions.function_file`)."""
    return function_file(RECORD_FORMAT, (model.content_hash(), held, actuators))


@functools.lru_cache(maxsize=32)
def _phase_function(model: RobotModel, held: tuple[str, ...], actuators: tuple[str, ...]
                    ) -> ca.Function:
    """``(x, u) -> (qdd, forces, u_full)`` of a phase as one SX function, from the disk cache
    (:func:`phase_function_file`) or built and saved there: building it (the Contact
    Algorithm in symbols) took 0.15 s per phase, a fifth of a whole 8 + 5 solve."""
    return disk_cached(phase_function_file(model, held, actuators),
                       lambda: _build_phase_function(model, held, actuators))


def _build_phase_function(model: RobotModel, held: tuple[str, ...],
                          actuators: tuple[str, ...]) -> ca.Function:
    nq = model.nq
    x = ca.SX.sym("x", 2 * nq)
    u = ca.SX.sym("u", len(actuators) + 2 * len(full.hold_axes(held)))
    point = full.phase_point(model, held, actuators, x, u)
    u_full = ca.vertcat(*full.full_controls(model, actuators, u[:len(actuators)]))
    forces = point.forces if held else ca.SX(0, 1)
    return ca.Function("record_full_phase", [x, u], [point.qdd, forces, u_full])


def _vec(value: Any, n: int) -> Array:
    return np.array([float(v) for v in as_scalars(value, n, "value")])


def full_phases_and_events(model: RobotModel, seq: ContactSequence, res: Any, step: float,
                           impulse: float) -> tuple[tuple[GaitPhase, ...], tuple[GaitEvent, ...]]:
    """The gait phases (knot values) and events of a full-coordinate result."""
    nq = model.nq
    phases, events = [], []
    for i, (spec, ph) in enumerate(zip(seq.phases, res.phases, strict=True)):
        acts = full.actuator_names(model, spec.held, ankle=_has_ankles(ph.controls, model))
        fn = _phase_function(model, spec.held, acts)
        qdd, forces, u_full = (np.asarray(o, dtype=float).T
                               for o in fn.map(ph.x.shape[0])(ph.x.T, ph.u.T))
        phases.append(GaitPhase(
            name=spec.name, contacts=tuple(hold_name(c) for c in spec.held), t=ph.t,
            q=ph.x[:, :nq], qd=ph.x[:, nq:],
            qdd=qdd, u=u_full,
            contact_forces={hold_name(c): forces[:, 2 * k:2 * k + 2]
                            for k, c in enumerate(spec.held)},
            state_names=tuple(ph.states), x=ph.x, xdot=ph.xdot,
            error_estimate=ph.error if np.all(np.isfinite(ph.error)) else None))
        ev = seq.events[i]
        q_end, qd_end = ph.x[-1, :nq], ph.x[-1, nq:]
        jump = full.event_map(model, seq, i, q_end, qd_end, impulse)
        leg = (ev.touchdown or ev.release)[0]
        impulses = {c: _vec(v, 2) for c, v in jump.impulses.items()}
        if not impulses and ev.release:
            impulses = {ev.release[0]: np.zeros(2)}
        events.append(GaitEvent(name=ev.name, t=float(ph.t[-1]), leg=leg, impulses=impulses,
                                qd_before=np.asarray(qd_end, dtype=float),
                                qd_after=_vec(jump.qd_after, nq)))
    if len(seq.phases) == 1 and seq.events[0].release:
        # The single-support walk: the rear tip leaves as the front one strikes.
        strike = events[0]
        events.append(GaitEvent(name="liftoff", t=strike.t, leg=seq.events[0].release[0],
                                impulses={seq.events[0].release[0]: np.zeros(2)},
                                qd_before=strike.qd_after, qd_after=strike.qd_after))
    return tuple(phases), tuple(events)


def _has_ankles(controls: tuple[str, ...], model: RobotModel) -> bool:
    contact_actuators = {a.name for a in model.actuators if a.contact is not None}
    return any(c in contact_actuators for c in controls)


def full_samples(model: RobotModel, res: Any, count: int,
                 points_fn: ca.Function, point_names: tuple[str, ...]) -> GaitSamples:
    """Dense samples of a full-coordinate result on ``count`` uniform times."""
    nq = model.nq
    total = sum(ph.duration for ph in res.phases)
    t0 = res.phases[0].t0
    t = t0 + np.linspace(0.0, total, count)
    q = np.zeros((count, nq))
    qd = np.zeros((count, nq))
    u = np.zeros((count, model.nu))
    bounds = [ph.tf for ph in res.phases]
    which = np.minimum(np.searchsorted(bounds, t, side="left"), len(res.phases) - 1)
    for i, ph in enumerate(res.phases):
        mask = which == i
        if not mask.any():
            continue
        x = np.atleast_2d(ph.x_at(t[mask]))
        uc = np.atleast_2d(ph.u_at(t[mask]))
        q[mask], qd[mask] = x[:, :nq], x[:, nq:]
        for j, name in enumerate(ph.controls):
            if name in {a.name for a in model.actuators}:
                u[mask, model.actuator_index(name)] = uc[:, j]
    pts = np.asarray(points_fn.map(count)(q.T), dtype=float)
    pts = pts.T.reshape(count, len(point_names), 2)
    points = {name: pts[:, j, :] for j, name in enumerate(point_names)}
    return GaitSamples(t=t, q=q, qd=qd, u=u, points=points)


def full_record(solution: StagedRun, seq: ContactSequence) -> RecordParts:
    """The phases, events and samples of a full-coordinate solution on its contact sequence
    ``seq``."""
    model, res = solution.model, solution.result
    step = res.parameters["step_length"]
    # IPOPT may end a hair outside a bound (its bound_relax_factor): the impulse is >= 0.
    impulse = max(res.parameters["impulse"], 0.0)
    total = sum(ph.duration for ph in res.phases)
    count = max(101, int(np.ceil(total * SAMPLE_RATE)) + 1)
    phases, events = full_phases_and_events(model, seq, res, step, impulse)
    samples = full_samples(model, res, count, points_function(model), point_names(model))
    return RecordParts(phases, events, samples)
