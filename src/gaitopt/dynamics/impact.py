"""The Collision Algorithm (paper eq. 11) and the liftoff impulse.

Impact: an inelastic collision makes the velocity of every listed contact point zero (the tip
that strikes and any tip that stays on the ground). With ``J``, ``Lambda`` and ``M^-1 J^T`` of
those contacts (see :mod:`.contact`)::

    impulses = -Lambda J qd_minus          (eq. 11; N s, world frame, [Px_1, Py_1, ...])
    qd_plus  = qd_minus + M^-1 J^T impulses

so ``J qd_plus = 0``. This is the velocity jump minimizing kinetic energy subject to the
constraints, so kinetic energy never increases.

Liftoff: an impulse of magnitude ``P >= 0`` (N s) at the lifting tip, along the leg axis from
the tip toward the hip (the origin of the first link below the base on the tip's chain),
``impulse_lifting = P e`` with ``e = (p_hip - p_tip) / |p_hip - p_tip|``, while the ``held``
tips stay fixed::

    dqd_P          = M^-1 J_l^T impulse_lifting
    impulses_held  = -Lambda_h J_h (qd_minus + dqd_P)
    qd_plus        = qd_minus + dqd_P + M^-1 J_h^T impulses_held

so ``J_h qd_plus = 0``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.aba import aba_sweep, articulated_inertias
from gaitopt.dynamics.backend import (
    Scalar,
    Scalars,
    as_scalar,
    dot,
    is_symbolic,
    sqrt,
    vector,
)
from gaitopt.dynamics.contact import constraint_system
from gaitopt.dynamics.kinematics import coordinates, link_poses, point_jacobian_rows
from gaitopt.dynamics.tree import contact_names, contact_point, hold_name, hold_specs
from gaitopt.robot.model import RobotModel


@dataclass(frozen=True)
class ImpactSolution:
    """``qd_plus`` ``(nq,)`` after the impact and ``impulses`` ``(2 nc,)`` (N s, ground on
    tips, world frame, stacked like contact forces)."""

    qd_plus: Any
    impulses: Any


@dataclass(frozen=True)
class LiftoffSolution:
    """``qd_plus`` ``(nq,)``; ``impulse_lifting`` ``(2,)`` the applied impulse (N s, world);
    ``impulses_held`` ``(2 n_held,)`` the ground impulses on the held tips."""

    qd_plus: Any
    impulse_lifting: Any
    impulses_held: Any


def impact_scalars(model: RobotModel, q: Scalars, qd_minus: Scalars,
                   names: Sequence[str]) -> tuple[Scalars, Scalars]:
    """:func:`impact` on scalar lists: ``(qd_plus, impulses)``."""
    if not names:
        return list(qd_minus), []
    system = constraint_system(model, q, names)
    tip_velocity = [dot(row, qd_minus) for row in system.jacobian]
    impulses = system.solve_impulse(tip_velocity)
    qd_plus = [v + d for v, d in zip(qd_minus, system.response(impulses), strict=True)]
    return qd_plus, impulses


def impact(model: RobotModel, q: Any, qd_minus: Any, contacts: Sequence[str]) -> ImpactSolution:
    """Inelastic impact at configuration ``q``: afterwards every contact in ``contacts`` has
    zero velocity. ``qd_minus`` ``(nq,)`` is the velocity just before."""
    names = hold_specs(model, contacts)
    qd_plus, impulses = impact_scalars(model, coordinates(model, q),
                                       coordinates(model, qd_minus, "qd_minus"), names)
    return ImpactSolution(vector(qd_plus), vector(impulses))


def hip_link(model: RobotModel, contact: str) -> int:
    """The first link below the base on the chain to ``contact`` (its origin is the hip)."""
    i, _ = contact_point(model, contact)
    chain = model.chain(i)
    if len(chain) < 2:
        raise ValueError(f"contact {contact!r} is on the floating base {model.base.name!r}: "
                         "it has no leg axis for a liftoff impulse")
    return chain[1]


def liftoff_scalars(model: RobotModel, q: Scalars, qd_minus: Scalars, lifting: str,
                    magnitude: Scalar, held: Sequence[str]
                    ) -> tuple[Scalars, Scalars, Scalars]:
    """:func:`liftoff_impulse` on scalars: ``(qd_plus, impulse_lifting, impulses_held)``."""
    art = articulated_inertias(model, q)
    poses = link_poses(model, q, art.x)
    i, p_local = contact_point(model, lifting)
    p_tip = poses[i].to_world(p_local)
    p_hip = poses[hip_link(model, lifting)].origin
    dx, dy = p_hip[0] - p_tip[0], p_hip[1] - p_tip[1]
    length = sqrt(dx * dx + dy * dy)
    if not is_symbolic(length) and not length > 1e-12:
        raise ValueError(f"liftoff: the tip {lifting!r} coincides with its hip; the leg axis "
                         "is undefined")
    impulse = [magnitude * dx / length, magnitude * dy / length]
    row_x, row_y = point_jacobian_rows(model, poses, i, p_tip)
    generalized = [rx * impulse[0] + ry * impulse[1] for rx, ry in zip(row_x, row_y,
                                                                       strict=True)]
    qd_mid = [v + d for v, d in zip(qd_minus, aba_sweep(art, generalized), strict=True)]
    if not held:
        return qd_mid, impulse, []
    system = constraint_system(model, q, held, art)
    impulses_held = system.solve_impulse([dot(row, qd_mid) for row in system.jacobian])
    qd_plus = [v + d for v, d in zip(qd_mid, system.response(impulses_held), strict=True)]
    return qd_plus, impulse, impulses_held


def liftoff_impulse(model: RobotModel, q: Any, qd_minus: Any, lifting: str, magnitude: Any,
                    held: Sequence[str] = ()) -> LiftoffSolution:
    """Velocity jump from a liftoff impulse of ``magnitude`` (N s, >= 0) at the tip
    ``lifting`` along its leg axis toward the hip, with the ``held`` tips kept fixed."""
    (lift,) = contact_names(model, (lifting,), "lifting")
    held_names = hold_specs(model, held, "held")
    if lift in (hold_name(h) for h in held_names):
        raise ValueError(f"liftoff: the lifting contact {lift!r} cannot also be held "
                         f"(held = {list(held_names)})")
    p = as_scalar(magnitude, "liftoff magnitude")
    if not is_symbolic(p) and p < 0.0:
        raise ValueError(f"liftoff magnitude must be >= 0 N s (it pushes the tip toward the "
                         f"hip), got {p}")
    qd_plus, impulse, impulses_held = liftoff_scalars(
        model, coordinates(model, q), coordinates(model, qd_minus, "qd_minus"), lift, p,
        held_names)
    return LiftoffSolution(vector(qd_plus), vector(impulse), vector(impulses_held))
