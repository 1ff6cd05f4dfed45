"""The Contact Algorithm (paper Appendix 1, eqs. 7-10): dynamics with tips held on the ground.

Each held contact point is a 2-d pin constraint ``c(q) = p_tip_world - p_ground = 0``, or with
the hold spec ``name:y`` its normal row only (:class:`gaitopt.dynamics.tree.Hold`; the second
point of a flat foot). With ``J`` the stacked rows ``(m, nq)`` (``m = 2 nc`` for pins, rows
``x_1, y_1, x_2, y_2, ...``; a normal-only hold contributes its ``y`` row alone):

* ``qdd_free = M^-1 (tau - C - G - D qd)`` (ABA; ``D`` the joints' damping),
* ``Lambda = (J M^-1 J^T)^-1`` ``(2 nc, 2 nc)``, the operational-space inertia,
* ``forces = -Lambda (J qdd_free + Jdot qd)`` (eq. 9): the force of the ground on each tip,
  world frame, N, stacked ``[fx_1, fy_1, fx_2, fy_2, ...]``,
* ``qdd = qdd_free + M^-1 J^T forces`` (eq. 10), which makes ``J qdd + Jdot qd = 0``.

Recursive evaluation: ``M`` is never formed. The articulated-body inertias of the ABA are
computed once per configuration; ``qdd_free`` and each column of ``M^-1 J^T`` are then one
O(n) ABA sweep each (the column for row ``r`` of ``J`` is the acceleration response to the
generalized force ``J[r]^T``, i.e. a unit force at the tip). ``Jdot qd`` is the tip
acceleration at ``qdd = 0`` from the outward velocity pass. Only the small ``2 nc x 2 nc``
matrix ``J M^-1 J^T`` is factorized (``L D L^T`` in scalars).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.aba import (
    ArticulatedInertias,
    VelocityTerms,
    aba_sweep,
    articulated_inertias,
    velocity_terms,
)
from gaitopt.dynamics.backend import Scalars, dot, matrix, spd_inverse, vector
from gaitopt.dynamics.kinematics import (
    Pose,
    body_accelerations,
    coordinates,
    link_poses,
    point_acceleration_world,
    point_jacobian_rows,
)
from gaitopt.dynamics.rnea import add_damping, gravity_acceleration
from gaitopt.dynamics.tree import contact_point, hold_specs, holds
from gaitopt.robot.model import RobotModel


@dataclass(frozen=True)
class ConstraintSystem:
    """The configuration-dependent quantities of a set of held contacts (scalars).

    ``jacobian``: rows of ``J`` ``(2 nc, nq)``; ``minv_jt``: columns of ``M^-1 J^T`` (one list
    of ``nq`` per row of ``J``); ``lam``: rows of ``Lambda`` ``(2 nc, 2 nc)``.
    """

    names: tuple[str, ...]
    art: ArticulatedInertias
    poses: list[Pose]
    jacobian: list[Scalars]
    minv_jt: list[Scalars]
    lam: list[Scalars]

    def solve_impulse(self, velocity_error: Scalars) -> Scalars:
        """``-Lambda e``: the impulses (forces) that cancel a tip velocity (acceleration)
        ``e``."""
        return [-dot(row, velocity_error) for row in self.lam]

    def response(self, forces: Scalars) -> Scalars:
        """``M^-1 J^T forces`` ``(nq,)``."""
        nq = len(self.art.tree)
        out: Scalars = [0.0] * nq
        for col, f in zip(self.minv_jt, forces, strict=True):
            out = [o + c * f for o, c in zip(out, col, strict=True)]
        return out


def constraint_system(model: RobotModel, q: Scalars, names: Sequence[str],
                      art: ArticulatedInertias | None = None) -> ConstraintSystem:
    """``J``, ``M^-1 J^T`` and ``Lambda`` for the contacts ``names`` at ``q`` (scalars)."""
    if art is None:
        art = articulated_inertias(model, q)
    poses = link_poses(model, q, art.x)
    jac: list[Scalars] = []
    for hold in holds(model, names):
        i, p = contact_point(model, hold.name)
        rows = point_jacobian_rows(model, poses, i, poses[i].to_world(p))
        jac.extend(rows[a] for a in hold.axes)
    minv_jt = [aba_sweep(art, row) for row in jac]
    lam_inv = [[dot(jr, col) for col in minv_jt] for jr in jac]
    what = f"J M^-1 J^T of contacts {', '.join(names)}"
    lam = spd_inverse(lam_inv, what) if jac else []
    return ConstraintSystem(tuple(names), art, poses, jac, minv_jt, lam)


def contact_bias_accelerations(model: RobotModel, system: ConstraintSystem,
                               terms: VelocityTerms) -> Scalars:
    """``Jdot qd`` ``(2 nc,)``: the tips' world accelerations at ``qdd = 0``."""
    tree, x = system.art.tree, system.art.x
    a = body_accelerations(tree, x, terms.c, [0.0] * len(tree))
    out: Scalars = []
    for hold in holds(model, system.names):
        i, p = contact_point(model, hold.name)
        b = model.coordinate_of_link(i)
        acc = point_acceleration_world(system.poses[i], terms.v[b], a[b], p)
        out.extend(acc[k] for k in hold.axes)
    return out


@dataclass(frozen=True)
class ContactSolution:
    """Result of :func:`contact_dynamics`.

    ``qdd`` ``(nq,)``: constrained accelerations; ``forces`` ``(2 nc,)``: ground forces on the
    tips, world frame, N, ``[fx_1, fy_1, ...]``; ``Lambda`` ``(2 nc, 2 nc)``:
    ``(J M^-1 J^T)^-1`` (kg).
    """

    qdd: Any
    forces: Any
    Lambda: Any


def contact_dynamics_scalars(model: RobotModel, q: Scalars, qd: Scalars, tau: Scalars,
                             names: Sequence[str]) -> tuple[Scalars, Scalars, list[Scalars]]:
    """:func:`contact_dynamics` on scalar lists: ``(qdd, forces, Lambda rows)``."""
    art = articulated_inertias(model, q)
    terms = velocity_terms(art, qd)
    qdd_free = aba_sweep(art, add_damping(model, tau, qd, -1.0), terms.bias, terms.c,
                         gravity_acceleration(model))
    if not names:
        return qdd_free, [], []
    system = constraint_system(model, q, names, art)
    tip_acc_free = [dot(row, qdd_free) + b for row, b in
                    zip(system.jacobian, contact_bias_accelerations(model, system, terms),
                        strict=True)]
    forces = system.solve_impulse(tip_acc_free)
    qdd = [a + d for a, d in zip(qdd_free, system.response(forces), strict=True)]
    return qdd, forces, system.lam


def contact_dynamics(model: RobotModel, q: Any, qd: Any, tau: Any,
                     contacts: Sequence[str]) -> ContactSolution:
    """Accelerations and contact forces with the tips ``contacts`` held fixed on the ground.

    ``tau`` ``(nq,)`` are generalized forces (e.g. :func:`.actuation.generalized_forces` of
    hip, knee and ankle torques with the same held contacts). With no contacts this is the
    free dynamics (empty ``forces``).
    """
    names = hold_specs(model, contacts)
    qdd, forces, lam = contact_dynamics_scalars(
        model, coordinates(model, q), coordinates(model, qd, "qd"),
        coordinates(model, tau, "tau"), names)
    return ContactSolution(vector(qdd), vector(forces), matrix(lam, len(forces)))
