"""Checks of the full-coordinate fields at every knot of every phase.

At each knot of a phase with the contacts ``C`` held (``phase.contacts``), from ``q, qd, qdd``
(nq,), ``u`` (nu,) and the contact forces ``f`` (2 |C|,) of the file only:

* equations of motion ``M(q) qdd + h(q, qd) - B_C u - J_C(q)^T f = 0`` (nq,), evaluated with
  the RNEA (``rnea(q, qd, qdd, J^T f) - B u``) and the actuation of the held contacts
  (:func:`gaitopt.dynamics.actuation.generalized_forces`); the residual is measured relative to
  body weight x leg length (m g l, N m);
* each held tip at its ground point (leg 1 at x = 0, leg 2 at x = step length, y = 0), at rest
  (``J qd = 0``) and not accelerating (``J qdd + Jdot qd = 0``);
* the phase states: ``x`` equals the phase's map of ``(q, qd)`` and ``xdot`` its time
  derivative ``dx/dq qd + dx/dqd qdd`` (:func:`state_map`);
* normal forces ``f_y >= 0`` and, if the gait was solved with a friction coefficient mu,
  ``|f_x| <= mu f_y`` (also for the events' impulses on held tips);
* the parameters: speed x step time = step length, the single-support time is the first
  phase's duration, the liftoff impulse is the magnitude of the impulse on the lifting tip.

The events that apply the liftoff impulse (whose lifting tip is exempt from friction and
carries the parameter's magnitude) are those the file's contact sequence marks
(:func:`gaitopt.gait.formulations.cost.impulse_events`: ``liftoff`` in the walk, ``toe_off`` in the
heel-toe walk), by the name ``liftoff`` only in a file without a sequence.
"""

from __future__ import annotations

import functools

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from gaitopt.analysis.checks.check import Check, Worst
from gaitopt.dynamics.actuation import generalized_forces
from gaitopt.dynamics.function_cache import disk_cached, function_file
from gaitopt.dynamics.kinematics import (
    contact_acceleration,
    contact_jacobian,
    contact_position,
    contact_velocity,
)
from gaitopt.dynamics.reduced import N_DOUBLE, double_support_state
from gaitopt.dynamics.rnea import rnea
from gaitopt.gait.formulations.cost import impulse_events
from gaitopt.gait.formulations.reduced import physics as walking
from gaitopt.gait.record.file import Gait, GaitPhase
from gaitopt.gait.sequence.contact_sequence import phase_holds, sequence_from_dict
from gaitopt.robot.biped import biped_of
from gaitopt.robot.model import RobotModel

Array = NDArray[np.float64]


class UnknownStatesError(ValueError):
    """A phase's ``state_names`` are neither a reduced phase's nor the full coordinates'."""


def full_state_names(model: RobotModel) -> tuple[str, ...]:
    """State names of a full-coordinate phase: ``q`` names then ``<name>_rate`` of each."""
    names = model.coordinate_names
    return names + tuple(f"{n}_rate" for n in names)


@functools.lru_cache(maxsize=32)
def state_map(model: RobotModel, state_names: tuple[str, ...]) -> ca.Function:
    """``(q, qd, qdd) -> (x, xdot)`` of a phase with these ``state_names``.

    Full-coordinate phases (:func:`full_state_names`): ``x = [q, qd]``. Reduced phases (the
    names of :func:`gaitopt.gait.formulations.reduced.physics.state_names`): the existing reduced
    maps (:func:`~gaitopt.gait.formulations.reduced.physics.full_to_single_support`,
    :func:`~gaitopt.gait.formulations.reduced.physics.full_to_double_support`; hip polar about tip 1
    at the origin). ``xdot = dx/dq qd + dx/dqd qdd`` in both cases.

    Raises:
        UnknownStatesError: other state names.
    """
    q, qd, qdd = (ca.SX.sym(n, model.nq) for n in ("q", "qd", "qdd"))
    if state_names == full_state_names(model):
        x = ca.vertcat(q, qd)
    elif _reduced_phase(model, state_names) == walking.SINGLE:
        x = walking.full_to_single_support(model, q, qd)
    elif _reduced_phase(model, state_names) == walking.DOUBLE:
        x = walking.full_to_double_support(model, q, qd)
    else:
        raise _unknown(state_names)
    xdot = ca.jtimes(x, q, qd) + ca.jtimes(x, qd, qdd)
    return ca.Function("verify_states", [q, qd, qdd], [x, xdot])


@functools.lru_cache(maxsize=32)
def full_state_function(model: RobotModel, state_names: tuple[str, ...]) -> ca.Function:
    """``(x, L) -> (q, qd)``: the full state of phase states ``x`` (the inverse of
    :func:`state_map`; ``L`` the step length, where double support holds tip 2).

    Full-coordinate phases split ``x = [q, qd]``; reduced phases use the reduced maps
    (:func:`gaitopt.dynamics.reduced.single_support_state`, ``double_support_state``: tip 1 at
    the origin, tip 2 at ``(L, 0)``). Raises :class:`UnknownStatesError` for other names.
    """
    x = ca.SX.sym("x", len(state_names))
    step = ca.SX.sym("L")
    nq = model.nq
    if state_names == full_state_names(model):
        q, qd = x[:nq], x[nq:]
    elif _reduced_phase(model, state_names) == walking.SINGLE:
        q, qd = walking.single_support_to_full(model, x)
    elif _reduced_phase(model, state_names) == walking.DOUBLE:
        z, zd = walking.split_state(x, N_DOUBLE)
        q, qd = double_support_state(model, 0, z, zd, walking.ORIGIN, (step, 0.0))
    else:
        raise _unknown(state_names)
    return ca.Function("verify_full_state", [x, step], [q, qd])


def _reduced_phase(model: RobotModel, state_names: tuple[str, ...]) -> str | None:
    """The reduced phase (``walking.SINGLE`` / ``DOUBLE``) with these state names, if any."""
    for phase in (walking.SINGLE, walking.DOUBLE):
        try:
            if walking.state_names(model, phase) == state_names:
                return phase
        except ValueError:  # not the five-link biped: only full-coordinate phases
            return None
    return None


def _unknown(state_names: tuple[str, ...]) -> UnknownStatesError:
    return UnknownStatesError(
        f"phase state names {list(state_names)} are neither the full coordinates "
        "[q, q rates] nor a reduced phase's (single or double support)")


@functools.lru_cache(maxsize=32)
def knot_function(model: RobotModel, contacts: tuple[str, ...]) -> ca.Function:
    """``(q, qd, qdd, u, f) -> (eom (nq), position, velocity, acceleration (2 |C| each))``
    with the ``contacts`` C held; ``f`` (2 |C|) stacks their forces ``[fx, fy, ...]``.
    Cached on disk (:mod:`gaitopt.dynamics.function_cache`): traced once per model."""

    def build() -> ca.Function:
        q, qd, qdd = (ca.SX.sym(n, model.nq) for n in ("q", "qd", "qdd"))
        u = ca.SX.sym("u", model.nu)
        f = ca.SX.sym("f", 2 * len(contacts))
        if contacts:
            jac = contact_jacobian(model, q, list(contacts))
            eom = rnea(model, q, qd, qdd, jac.T @ f)
        else:
            eom = rnea(model, q, qd, qdd)
        eom = eom - generalized_forces(model, q, u, list(contacts))
        pos = [contact_position(model, q, c) for c in contacts]
        vel = [contact_velocity(model, q, qd, c) for c in contacts]
        acc = [contact_acceleration(model, q, qd, qdd, c) for c in contacts]
        return ca.Function("verify_knots", [q, qd, qdd, u, f],
                           [eom, ca.vertcat(*pos), ca.vertcat(*vel), ca.vertcat(*acc)])

    return disk_cached(function_file("verify_knots", (model.content_hash(), contacts)), build)


def ground_points(gait: Gait, phase: int | None = None) -> dict[str, Array]:
    """Where each held point stands in phase ``phase`` (world, m): from the gait's contact
    sequence (``anchor L + offset``, ``y = 0``, the phase's own anchors if it has some, as a
    stride's second step; ``x`` NaN for a point without an anchor, held along y only), or for
    a gait file without one, leg 1 at ``x = 0`` and leg 2 at ``x = L``."""
    step = gait.parameters["step_length"]
    if gait.contact_sequence is not None:
        seq = sequence_from_dict(dict(gait.contact_sequence))
        i = phase if phase is not None and phase < len(seq.phases) else None
        anchored = seq.anchored(i)
        return {c.name: np.array([seq.ground_x(c.name, step, i) if c.name in anchored
                                  else np.nan, 0.0]) for c in gait.model.contacts}
    stance, swing = biped_of(gait.model).contacts
    return {stance: np.array([0.0, 0.0]), swing: np.array([step, 0.0])}


def body_size(model: RobotModel) -> float:
    """The base's height above the lowest contact point in the pose with every coordinate 0
    (m): the length scale of the equations-of-motion residual."""
    zero = np.zeros(model.nq)
    low = min(float(np.asarray(contact_position(model, zero, c.name), dtype=float).ravel()[1])
              for c in model.contacts) if model.contacts else -1.0
    return max(-low, 0.1)


def _columns(fn: ca.Function, *args: Array) -> list[Array]:
    """Evaluate ``fn`` at K points (rows of each arg (K, n)); outputs as (K, m) arrays."""
    k = args[0].shape[0]
    out = fn.map(k)(*[a.T for a in args])
    outs = out if isinstance(out, tuple | list) else [out]
    return [np.asarray(o, dtype=float).T.reshape(k, -1) for o in outs]


def knot_checks(gait: Gait, lim: dict[str, float]) -> list[Check]:
    """``eom.residual``, ``contacts.*``, ``states.*`` at every knot (see the module)."""
    model = gait.model
    weight = model.total_mass * float(np.hypot(*model.gravity))
    scale = weight * body_size(model)
    worst = {k: Worst() for k in ("eom.residual", "contacts.position", "contacts.velocity",
                                  "contacts.acceleration", "contacts.normal_force",
                                  "states.values", "states.rates")}
    for i, ph in enumerate(gait.phases):
        contacts = tuple(ph.contacts)
        forces = (np.hstack([ph.contact_forces[c] for c in contacts]) if contacts
                  else np.zeros((ph.t.size, 0)))
        eom, pos, vel, acc = _columns(knot_function(model, contacts), ph.q, ph.qd, ph.qdd,
                                      ph.u, forces)
        at_ground = ground_points(gait, i)
        ground = np.hstack([at_ground[c] for c in contacts]) if contacts else np.zeros(0)
        x, xdot = _columns(state_map(model, tuple(ph.state_names)), ph.q, ph.qd, ph.qdd)
        per_knot = {
            "eom.residual": np.max(np.abs(eom), axis=1) / scale,
            # NaN ground x: a point held along y only, without an anchor (its x is free).
            "contacts.position": _row_max(np.nan_to_num(np.abs(pos - ground), nan=0.0)),
            "contacts.velocity": _row_max(np.abs(vel)),
            "contacts.acceleration": _row_max(np.abs(acc)),
            "contacts.normal_force": _row_max(-forces[:, 1::2]) / weight,
            "states.values": _row_max(np.abs(x - ph.x)),
            "states.rates": _row_max(_off_normal(
                model, ph, xdot - ph.xdot, phase_holds(gait.contact_sequence, i, contacts))),
        }
        for key, values in per_knot.items():
            k = int(np.argmax(values))
            worst[key] = worst[key].update(values[k], f"phases[{i}] ({ph.name}) knot {k}")
    worst["contacts.normal_force"] = Worst(max(0.0, worst["contacts.normal_force"].value),
                                           worst["contacts.normal_force"].where)
    checks = [w.check(key, lim) for key, w in worst.items()]
    friction = _friction_check(gait, lim)
    return checks + ([friction] if friction is not None else []) + [_parameter_check(gait, lim)]


def _off_normal(model: RobotModel, ph: GaitPhase, residual: Array,
                holds: tuple[str, ...]) -> Array:
    """``residual`` (K, 2 nq) of the state rates, less any part along the held points'
    constraint normals in a full-coordinate phase.

    The full formulation's rates are ``[qd + J^T gamma, qdd + J^T nu]``: the projection
    controls correct the collocation's drift off the constraint manifold and act only along
    ``J^T`` (docs/formulations.md). What is left after removing ``J^T (J J^T)^-1 J r`` from
    each half must vanish, as must the whole residual in a reduced phase or with no point
    held. ``holds``: the phase's hold specs (the rows of ``J``)."""
    if not ph.contacts or tuple(ph.state_names) != full_state_names(model):
        return residual
    nq = model.nq
    out = np.array(residual, dtype=float)
    for k in range(out.shape[0]):
        jac = np.asarray(contact_jacobian(model, ph.q[k], holds), dtype=float).reshape(-1, nq)
        for half in (slice(0, nq), slice(nq, 2 * nq)):
            r = out[k, half]
            out[k, half] = r - jac.T @ np.linalg.solve(jac @ jac.T, jac @ r)
    return np.abs(out)


def _row_max(a: Array) -> Array:
    """Largest entry of each row; 0 for rows without entries (no contacts held)."""
    return np.max(a, axis=1, initial=0.0) if a.shape[1] else np.zeros(a.shape[0])


def _friction_check(gait: Gait, lim: dict[str, float]) -> Check | None:
    mu = gait.options.get("friction")
    if mu is None:
        return None
    worst = Worst()
    for i, ph in enumerate(gait.phases):
        for c, f in ph.contact_forces.items():
            excess = np.abs(f[:, 0]) - mu * f[:, 1]
            k = int(np.argmax(excess))
            worst = worst.update(excess[k], f"phases[{i}] ({ph.name}) knot {k} {c}")
    lifting = impulse_events(gait)  # their lifting tips' pushes are not held by friction
    for j, e in enumerate(gait.events):
        for c, imp in e.impulses.items():
            if not (e in lifting and c == e.leg):
                worst = worst.update(abs(float(imp[0])) - mu * float(imp[1]),
                                     f"events[{j}] ({e.name}) {c}")
    return Check("contacts.friction", max(0.0, worst.value), lim["contacts.friction"],
                 worst.where)


def _parameter_check(gait: Gait, lim: dict[str, float]) -> Check:
    p = gait.parameters
    step, step_time = p["step_length"], p["step_time"]
    worst = Worst().update(abs(p["speed"] * step_time - step) / max(step, 1e-12),
                           "parameters.speed")
    t1 = gait.phases[0].duration
    worst = worst.update(abs(p["single_support_time"] - t1) / step_time,
                         "parameters.single_support_time")
    lifts = impulse_events(gait)
    if len(gait.phases) > 1 and lifts:
        imp = lifts[-1].impulses.get(lifts[-1].leg, np.zeros(2))
        magnitude = float(np.hypot(*imp))
        worst = worst.update(abs(magnitude - p["liftoff_impulse"]) /
                             max(p["liftoff_impulse"], 1.0), "parameters.liftoff_impulse")
    return worst.check("parameters.consistency", lim)
