"""The physics of one step in full coordinates: phase dynamics, events and the leg swap.

One code path for numbers and CasADi symbols (like
:mod:`gaitopt.gait.formulations.reduced.physics` for the reduced coordinates): the
full-coordinate problem (:mod:`gaitopt.gait.formulations.full.problem`) calls these on symbols,
the gait record (:mod:`gaitopt.gait.formulations.full.extract`) on numbers.
States ``x = [q, qd]`` (``2 nq``); a phase's controls are its actuator torques followed by
the projection controls ``gamma, nu`` of its held points (docs/formulations.md §1).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.actuation import generalized_forces
from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.dynamics.contact import contact_dynamics
from gaitopt.dynamics.impact import impact, liftoff_impulse
from gaitopt.dynamics.kinematics import contact_jacobian
from gaitopt.dynamics.tree import HOLD_AXES, hold_name
from gaitopt.gait.sequence.contact_sequence import ContactSequence, EventSpec
from gaitopt.robot.model import BASE_X, RobotModel
from gaitopt.robot.symmetry import LegSwap, identity_swap, leg_swap


def period_map(model: RobotModel, seq: ContactSequence) -> LegSwap:
    """The map from the end of ``seq`` to its start: the leg swap for one step
    (:func:`~gaitopt.robot.symmetry.leg_swap`), the identity for a stride (``seq.steps =
    2``: no symmetry assumed)."""
    return leg_swap(model) if seq.steps == 1 else identity_swap(model)


def state_names(model: RobotModel) -> tuple[str, ...]:
    """``[q, qd]`` names: the coordinates, then ``<coordinate>_rate``."""
    names = model.coordinate_names
    return names + tuple(f"{n}_rate" for n in names)


def hold_axes(held: Sequence[str]) -> list[tuple[str, int]]:
    """``(contact, axis)`` of each constraint row of the hold specs ``held`` (axis 0 = x,
    1 = y; :func:`gaitopt.dynamics.tree.holds`), in the Contact Algorithm's row order."""
    out = []
    for spec in held:
        name, _, axes = spec.partition(":")
        out += [(name, a) for a in HOLD_AXES[axes or "xy"]]
    return out


def projection_names(held: Sequence[str]) -> tuple[str, ...]:
    """Names of the projection controls of the held points (one ``gamma`` and one ``nu``
    per constraint row)."""
    rows = hold_axes(held)
    return tuple(f"{kind}_{c}_{'xy'[a]}" for kind in ("gamma", "nu") for c, a in rows)


def per_point(held: Sequence[str], flat: Any) -> dict[str, Any]:
    """Row-stacked forces or impulses of the held points -> ``(2,)`` per point by name (world
    x, y; zero along an axis the point is not held on)."""
    rows = hold_axes(held)
    values = as_scalars(flat, len(rows), "forces") if rows else []
    out: dict[str, list[Any]] = {}
    for (c, a), value in zip(rows, values, strict=True):
        out.setdefault(c, [0.0, 0.0])[a] = value
    return {c: vector(v) for c, v in out.items()}


def actuator_names(model: RobotModel, held: Sequence[str], *, ankle: bool) -> tuple[str, ...]:
    """Actuators acting in a phase, in model order: the joint actuators, and the contact
    actuators of held points when ``ankle``."""
    return tuple(a.name for a in model.actuators
                 if a.joint is not None or (ankle and a.contact in held))


def full_controls(model: RobotModel, names: Sequence[str], u: Any) -> list[Any]:
    """The model's actuator vector (nu,) from the first ``len(names)`` entries of ``u``."""
    values = as_scalars(u, len(names), "u") if len(names) else []
    out: list[Any] = [0.0] * model.nu
    for name, value in zip(names, values, strict=True):
        out[model.actuator_index(name)] = value
    return out


@dataclass(frozen=True)
class PointValues:
    """What the phase dynamics computes at one point."""

    xdot: Any
    qdd: Any
    forces: Any


def phase_point(model: RobotModel, held: Sequence[str], actuators: Sequence[str], x: Any,
                u: Any) -> PointValues:
    """``xdot = [qd + J^T gamma, qdd + J^T nu]`` with ``qdd, f`` from the Contact Algorithm
    (``u`` = actuator torques then projection controls). ``forces`` ``(2 n_held,)``: per held
    point ``[fx, fy]`` (0 along an axis it is not held on)."""
    nq, na = model.nq, len(actuators)
    m = len(hold_axes(held))
    xs = as_scalars(x, 2 * nq, "x")
    q, qd = xs[:nq], xs[nq:]
    us = as_scalars(u, na + 2 * m, "u")
    tau = generalized_forces(model, vector(q), vector(full_controls(model, actuators,
                                                                    us[:na])), held)
    sol = contact_dynamics(model, vector(q), vector(qd), tau, held)
    qdd = as_scalars(sol.qdd, nq, "qdd")
    dq, dqd = list(qd), list(qdd)
    if held:
        gamma, nu = us[na:na + m], us[na + m:na + 2 * m]
        jac = contact_jacobian(model, vector(q), held)
        for r in range(m):
            for j in range(nq):
                dq[j] = dq[j] + jac[r, j] * gamma[r]
                dqd[j] = dqd[j] + jac[r, j] * nu[r]
    forces = per_point(held, sol.forces)
    stacked = [f for spec in held for f in as_scalars(forces[hold_name(spec)], 2, "f")]
    return PointValues(xdot=vector(dq + dqd), qdd=sol.qdd, forces=vector(stacked))


@dataclass(frozen=True)
class EventValues:
    """A velocity jump: ``qd_after`` (nq,) and the impulses on each point by name (2,)."""

    qd_after: Any
    impulses: dict[str, Any]


def event_map(model: RobotModel, seq: ContactSequence, i: int, q: Any, qd: Any,
              impulse: Any) -> EventValues:
    """Event ``i``: impact of the points held afterwards (as the next phase holds them) if
    any touch down; else the liftoff impulse of magnitude ``impulse`` (N s) on the released
    point; else nothing. Impulses ``(2,)`` per point as in :func:`per_point`."""
    ev: EventSpec = seq.events[i]
    after = seq.holds_after(i, period_map(model, seq).contacts)
    if ev.touchdown:
        sol = impact(model, q, qd, after)
        return EventValues(sol.qd_plus, per_point(after, sol.impulses))
    if ev.impulse:
        lift = liftoff_impulse(model, q, qd, ev.release[0], impulse, after)
        out = {ev.release[0]: lift.impulse_lifting}
        if after:
            out |= per_point(after, lift.impulses_held)
        return EventValues(lift.qd_plus, out)
    return EventValues(qd, {})


def event_impulses(model: RobotModel, seq: ContactSequence, i: int, x: Any, impulse: Any
                   ) -> dict[str, Any]:
    """The impulses of event ``i`` as the constraints see them (N s, by point).

    A touchdown's impact impulses come from the state ``x = [q, qd]`` before it. A release's
    impulses on the held points are evaluated with ``qd = 0``: the held points stand still
    before the release (``J qd = 0``, enforced at the phase's last knot), so this is the same
    value, written without the dependence on those rows (which would make the constraint a
    combination of them, a degenerate NLP when the impulse is 0)."""
    nq = model.nq
    xs = as_scalars(x, 2 * nq, "x")
    q = vector(xs[:nq])
    qd = vector(xs[nq:]) if seq.events[i].touchdown else vector([0.0] * nq)
    return event_map(model, seq, i, q, qd, impulse).impulses


def swap_state(model: RobotModel, symmetry: LegSwap, q: Any, qd: Any, step: Any
               ) -> tuple[list[Any], list[Any]]:
    """The next period's ``(q, qd)``: ``S_q q`` and ``S_q qd`` (the legs swapped,
    :func:`~gaitopt.robot.symmetry.swap_matrices`; the identity for a stride:
    :func:`period_map`), ``x`` moved back by ``step`` (m: the step length, or the stride's
    for a stride)."""
    qs, qds = as_scalars(q, model.nq, "q"), as_scalars(qd, model.nq, "qd")
    q_next = symmetry.swap_q(qs)
    q_next[BASE_X] = q_next[BASE_X] - step
    return q_next, symmetry.swap_q(qds)
