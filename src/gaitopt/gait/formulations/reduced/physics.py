"""The physics of one walking step in reduced coordinates: phases, transitions and measures.

One code path for numbers and CasADi symbols: the OCP
(``gaitopt.gait.formulations.reduced.problem``) calls these
functions on symbols, the gait file writer and the checks call them on numbers.

A step (``docs/walking.md``): leg 1 (``Biped.stance``) stands with its tip at the origin.

* phase ``single_support``: state ``x = [z, zd]`` with ``z = [r, alpha, torso, hip_2,
  knee_2]`` (hip polar about tip 1, swing leg 2), 10 states;
* heel strike of tip 2 at ``(L, 0)``: inelastic impact with both tips held afterwards;
* phase ``double_support``: ``z = [r, alpha, torso]`` (hip polar about tip 1), 6 states;
* liftoff of tip 1 with an impulse of magnitude ``P`` along its leg (tip to hip) while tip 2
  stays; relabelling the legs (leg 2 becomes leg 1) and measuring the hip about tip 2 gives
  the next step's single-support state, which periodicity equates to the first.

With ``single_support_fraction = 1`` there is no double support: the heel strike of tip 2 is
an impact of tip 2 alone, tip 1 leaves the ground at that instant, and the relabelled state
starts the next step.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.actuation import generalized_forces
from gaitopt.dynamics.backend import Scalar, Scalars, as_scalars, cos, sin, sqrt, vector
from gaitopt.dynamics.impact import impact, liftoff_impulse
from gaitopt.dynamics.kinematics import contact_velocity, point_position
from gaitopt.dynamics.reduced import (
    N_DOUBLE,
    N_SINGLE,
    ReducedSolution,
    double_support_coordinates,
    double_support_dynamics,
    double_support_state,
    polar_from_hip,
    single_support_coordinates,
    single_support_dynamics,
    single_support_state,
)
from gaitopt.robot.biped import Leg, reduced_biped
from gaitopt.robot.model import RobotModel

SINGLE = "single_support"
DOUBLE = "double_support"
ORIGIN = (0.0, 0.0)


def state_names(model: RobotModel, phase: str) -> tuple[str, ...]:
    """Names of the phase's states ``x = [z, zd]`` (rates end in ``_rate``)."""
    biped = reduced_biped(model)
    z: tuple[str, ...]
    if phase == SINGLE:
        z = ("r", "alpha", "torso", biped.swing.hip, biped.swing.knee)
    elif phase == DOUBLE:
        z = ("r", "alpha", "torso")
    else:
        raise ValueError(f"unknown phase {phase!r}")
    return z + tuple(f"{name}_rate" for name in z)


def control_names(model: RobotModel, phase: str, *, ankle: bool) -> tuple[str, ...]:
    """Actuators active in a phase, in model order: every joint actuator, plus the ankle
    actuators of the tips on the ground when ``ankle``."""
    biped = reduced_biped(model)
    on_ground = {biped.stance.contact} if phase == SINGLE else set(biped.contacts)
    names = []
    for a in model.actuators:
        if a.joint is not None or (ankle and a.contact in on_ground):
            names.append(a.name)
    return tuple(names)


def full_controls(model: RobotModel, names: Sequence[str], u: Any) -> Scalars:
    """The model's actuator vector (nu,) with the entries ``names`` taken from ``u`` and the
    others zero."""
    values = as_scalars(u, len(names), "u", names)
    full: Scalars = [0.0] * model.nu
    for name, value in zip(names, values, strict=True):
        full[model.actuator_index(name)] = value
    return full


def split_state(x: Any, n: int) -> tuple[Scalars, Scalars]:
    """``(z, zd)`` from ``x = [z, zd]`` of ``2 n`` entries."""
    xs = as_scalars(x, 2 * n, "x")
    return xs[:n], xs[n:]


@dataclass(frozen=True)
class PhasePoint:
    """Everything the phase dynamics computes at one point (full state, forces, ...)."""

    xdot: Any
    solution: ReducedSolution


def single_support_point(model: RobotModel, x: Any, u: Any, controls: Sequence[str]
                         ) -> PhasePoint:
    """Reduced dynamics ``xdot = [zd, zdd]`` in single support on leg 1 (tip at the origin)."""
    biped = reduced_biped(model)
    z, zd = split_state(x, N_SINGLE)
    q, _ = single_support_state(model, 0, z, zd, ORIGIN)
    tau = generalized_forces(model, q, full_controls(model, controls, u), [biped.stance.contact])
    sol = single_support_dynamics(model, 0, z, zd, tau, ORIGIN)
    zdd = as_scalars(sol.zdd, N_SINGLE, "zdd")
    return PhasePoint(xdot=vector(list(zd) + zdd), solution=sol)


def double_support_point(model: RobotModel, x: Any, u: Any, controls: Sequence[str],
                         step_length: Scalar) -> PhasePoint:
    """Reduced dynamics in double support, tip 1 at the origin and tip 2 at ``(L, 0)``."""
    biped = reduced_biped(model)
    z, zd = split_state(x, N_DOUBLE)
    front = (step_length, 0.0)
    q, _ = double_support_state(model, 0, z, zd, ORIGIN, front)
    held = list(biped.contacts)
    tau = generalized_forces(model, q, full_controls(model, controls, u), held)
    sol = double_support_dynamics(model, 0, z, zd, tau, ORIGIN, front)
    zdd = as_scalars(sol.zdd, N_DOUBLE, "zdd")
    return PhasePoint(xdot=vector(list(zd) + zdd), solution=sol)


@dataclass(frozen=True)
class Transition:
    """A velocity jump at an event.

    Attributes:
        x_next: the state the next phase starts from.
        q: configuration at the event (nq,); qd_before, qd_after: velocities (nq,).
        impulses: impulses of the ground on each tip involved, by contact name (2,) (N s),
            the applied liftoff impulse included.
    """

    x_next: Any
    q: Any
    qd_before: Any
    qd_after: Any
    impulses: dict[str, Any]


def _pairs(values: Any, names: Sequence[str]) -> dict[str, Any]:
    flat = as_scalars(values, 2 * len(names), "impulses")
    return {name: vector(flat[2 * i:2 * i + 2]) for i, name in enumerate(names)}


def relabelled_single_support_state(model: RobotModel, q: Any, qd: Any,
                                    p_new_stance: Sequence[Scalar]) -> Any:
    """The next step's single-support state ``x = [z, zd]`` once leg 2 stands at
    ``p_new_stance``: hip polar about tip 2 and leg 1 as the swing leg, which the relabelling
    turns into "leg 2" of the next step."""
    z, zd = single_support_coordinates(model, 1, q, qd, p_new_stance)
    return vector(as_scalars(z, N_SINGLE, "z") + as_scalars(zd, N_SINGLE, "zd"))


def heel_strike(model: RobotModel, x_end: Any, step_length: Scalar, *,
                double_support: bool) -> Transition:
    """The inelastic impact of tip 2 at the end of single support.

    With double support following, tip 1 stays held during the impact and the result is the
    double-support state (positions unchanged, rates from the post-impact velocities). Without
    it, tip 2 strikes alone and the result is the relabelled single-support state of the next
    step.
    """
    biped = reduced_biped(model)
    z, zd = split_state(x_end, N_SINGLE)
    q, qd_minus = single_support_state(model, 0, z, zd, ORIGIN)
    contacts = list(biped.contacts) if double_support else [biped.swing.contact]
    sol = impact(model, q, qd_minus, contacts)
    if double_support:
        qs, qds = as_scalars(q, model.nq, "q"), as_scalars(sol.qd_plus, model.nq, "qd")
        base = biped.base_position
        _, _, rd, alphad = polar_from_hip(ORIGIN, qs[base], qds[base])
        x_next = vector([*z[:N_DOUBLE], rd, alphad, qds[biped.base_angle]])
    else:
        x_next = relabelled_single_support_state(model, q, sol.qd_plus, (step_length, 0.0))
    return Transition(x_next=x_next, q=q, qd_before=qd_minus, qd_after=sol.qd_plus,
                      impulses=_pairs(sol.impulses, contacts))


def liftoff(model: RobotModel, x_end: Any, step_length: Scalar, impulse: Scalar
            ) -> Transition:
    """Liftoff of tip 1 at the end of double support with an impulse of magnitude ``impulse``
    (N s) along leg 1 from tip to hip, tip 2 held; returns the relabelled single-support
    state of the next step."""
    biped = reduced_biped(model)
    z, zd = split_state(x_end, N_DOUBLE)
    front = (step_length, 0.0)
    q, qd_minus = double_support_state(model, 0, z, zd, ORIGIN, front)
    sol = liftoff_impulse(model, q, qd_minus, biped.stance.contact, impulse,
                          [biped.swing.contact])
    x_next = relabelled_single_support_state(model, q, sol.qd_plus, front)
    impulses = {biped.stance.contact: sol.impulse_lifting,
                **_pairs(sol.impulses_held, [biped.swing.contact])}
    return Transition(x_next=x_next, q=q, qd_before=qd_minus, qd_after=sol.qd_plus,
                      impulses=impulses)


def tip_height(model: RobotModel, q: Any, leg: Leg) -> Scalar:
    """Height (m) of a leg's tip above the ground (world y)."""
    c = model.contact(leg.contact)
    p = point_position(model, q, c.link, model.link(c.link).local_point(*c.at))
    return as_scalars(p, 2, "p")[1]


def tip_vertical_velocity(model: RobotModel, q: Any, qd: Any, leg: Leg) -> Scalar:
    """Vertical velocity (m/s) of a leg's tip."""
    return as_scalars(contact_velocity(model, q, qd, leg.contact), 2, "v")[1]


def front_leg_reach(x_end_or_x: Any, step_length: Scalar) -> Scalar:
    """Distance (m) from the hip to tip 2 at ``(L, 0)`` in double support."""
    z, _ = split_state(x_end_or_x, N_DOUBLE)
    r, alpha = z[0], z[1]
    dx = step_length + r * sin(alpha)
    dy = -r * cos(alpha)
    return sqrt(dx * dx + dy * dy)


def single_support_to_full(model: RobotModel, x: Any) -> tuple[Any, Any]:
    """Full ``(q, qd)`` of a single-support state."""
    z, zd = split_state(x, N_SINGLE)
    return single_support_state(model, 0, z, zd, ORIGIN)


def full_to_single_support(model: RobotModel, q: Any, qd: Any) -> Any:
    """Single-support state ``x`` (stance leg 1 at the origin) of a full state."""
    z, zd = single_support_coordinates(model, 0, q, qd, ORIGIN)
    return vector(as_scalars(z, N_SINGLE, "z") + as_scalars(zd, N_SINGLE, "zd"))


def full_to_double_support(model: RobotModel, q: Any, qd: Any) -> Any:
    """Double-support state ``x`` (hip polar about tip 1 at the origin) of a full state."""
    z, zd = double_support_coordinates(model, 0, q, qd, ORIGIN)
    return vector(as_scalars(z, N_DOUBLE, "z") + as_scalars(zd, N_DOUBLE, "zd"))
