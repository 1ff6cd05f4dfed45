"""Forward dynamics by the articulated-body algorithm (ABA), never forming or inverting M.

``qdd = M^-1 (tau - C qd - G)`` in three passes (Featherstone, 1-dof joints, body
coordinates, see :mod:`.tree`):

1. outward: ``v_k``, ``c_k = v_k x S_k qd_k``, ``IA_k = I_k``, ``pA_k = v_k x* I_k v_k``;
2. inward: ``U_k = IA_k S_k``, ``D_k = S_k^T U_k``, ``u_k = tau_k - S_k^T pA_k``,
   ``Ia = IA_k - U_k U_k^T / D_k``, ``pa = pA_k + Ia c_k + U_k u_k / D_k``,
   ``IA_parent += X_k^T Ia X_k``, ``pA_parent += X_k^T pa``;
3. outward: ``a' = X_k a_parent + c_k`` (``a_0 = -g``), ``qdd_k = (u_k - U_k^T a') / D_k``,
   ``a_k = a' + S_k qdd_k``.

The articulated inertias depend on ``q`` only, so they are computed once
(:func:`articulated_inertias`) and reused by :func:`aba_sweep` for several right-hand sides:
:func:`inverse_mass_times` evaluates ``M^-1 x`` in O(n) per vector this way, which the
contact, impact and liftoff algorithms use for ``M^-1 J^T``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.backend import Scalar, Scalars, vector
from gaitopt.dynamics.kinematics import body_velocities, coordinates, velocity_products
from gaitopt.dynamics.rnea import add_damping, gravity_acceleration
from gaitopt.dynamics.spatial import (
    ZERO3,
    ZERO_MAT3,
    Mat3,
    Transform,
    Vec3,
    add3,
    add_mat3,
    cross_force,
    dot3,
    force_to_parent,
    inertia_matrix,
    inertia_times,
    mat3_times,
    mat3_to_parent,
    motion_to_child,
    scale3,
)
from gaitopt.dynamics.tree import Body, bodies, joint_transforms
from gaitopt.robot.model import RobotModel


@dataclass(frozen=True)
class ArticulatedInertias:
    """Configuration-only part of the ABA: per body ``U_k = IA_k S_k`` (3-vector), ``D_k``
    (scalar), ``1 / D_k`` and the projected inertia ``Ia_k = IA_k - U_k U_k^T / D_k``
    (3x3, symmetric)."""

    tree: tuple[Body, ...]
    x: tuple[Transform, ...]
    u: tuple[Vec3, ...]
    d: tuple[Scalar, ...]
    d_inv: tuple[Scalar, ...]
    projected: tuple[Mat3, ...]


def articulated_inertias(model: RobotModel, q: Scalars) -> ArticulatedInertias:
    """Pass 2 of the ABA for the inertias only (depends on ``q`` alone)."""
    tree = bodies(model)
    x = joint_transforms(tree, q)
    n = len(tree)
    ia: list[Mat3] = [inertia_matrix(body.inertia) for body in tree]
    u: list[Vec3] = [ZERO3] * n
    d: list[Scalar] = [0.0] * n
    projected: list[Mat3] = [ZERO_MAT3] * n
    d_inv: list[Scalar] = [0.0] * n
    for k in reversed(range(n)):
        body = tree[k]
        col = ia[k][body.axis]  # IA is symmetric: column axis = row axis
        u[k] = col
        d[k] = col[body.axis]
        d_inv[k] = 1.0 / d[k]
        if body.parent >= 0:
            w = scale3(d_inv[k], col)
            upper = {(i, j): ia[k][i][j] - w[i] * col[j] for i in range(3) for j in range(i, 3)}
            projected[k] = tuple(tuple(upper[min(i, j), max(i, j)] for j in range(3))
                                 for i in range(3))  # type: ignore[assignment]
            ia[body.parent] = add_mat3(ia[body.parent], mat3_to_parent(x[k], projected[k]))
    return ArticulatedInertias(tree, tuple(x), tuple(u), tuple(d), tuple(d_inv),
                               tuple(projected))


def aba_sweep(art: ArticulatedInertias, tau: Sequence[Scalar],
              bias: Sequence[Vec3] | None = None, c: Sequence[Vec3] | None = None,
              a_root: Vec3 = ZERO3) -> Scalars:
    """Passes 2 (bias forces) and 3 of the ABA: ``qdd`` for generalized forces ``tau``.

    ``bias`` are the initial ``pA_k`` (velocity-product forces minus external forces), ``c``
    the velocity-product accelerations, ``a_root`` the world acceleration (``-g``). With all
    three zero the result is ``M^-1 tau``.
    """
    tree = art.tree
    n = len(tree)
    p_a: list[Vec3] = list(bias) if bias is not None else [ZERO3] * n
    u_k: Scalars = [0.0] * n
    for k in reversed(range(n)):
        body = tree[k]
        u_k[k] = tau[k] - p_a[k][body.axis]
        if body.parent >= 0:
            pa = add3(p_a[k], scale3(u_k[k] * art.d_inv[k], art.u[k]))
            if c is not None:
                pa = add3(pa, mat3_times(art.projected[k], c[k]))
            p_a[body.parent] = add3(p_a[body.parent], force_to_parent(art.x[k], pa))
    qdd: Scalars = [0.0] * n
    a: list[Vec3] = [ZERO3] * n
    for k, body in enumerate(tree):
        a_prime = motion_to_child(art.x[k], a[body.parent] if body.parent >= 0 else a_root)
        if c is not None:
            a_prime = add3(a_prime, c[k])
        qdd[k] = (u_k[k] - dot3(art.u[k], a_prime)) * art.d_inv[k]
        a_list = list(a_prime)
        a_list[body.axis] = a_list[body.axis] + qdd[k]
        a[k] = (a_list[0], a_list[1], a_list[2])
    return qdd


@dataclass(frozen=True)
class VelocityTerms:
    """Pass 1 of the ABA per body: spatial velocity ``v``, bias force
    ``bias = v x* I v`` and velocity-product acceleration ``c = v x S qd``."""

    v: list[Vec3]
    bias: list[Vec3]
    c: list[Vec3]


def velocity_terms(art: ArticulatedInertias, qd: Scalars) -> VelocityTerms:
    """Pass 1 of the ABA (see :class:`VelocityTerms`)."""
    v = body_velocities(art.tree, art.x, qd)
    c = velocity_products(art.tree, v, qd)
    bias = [cross_force(v[k], inertia_times(body.inertia, v[k]))
            for k, body in enumerate(art.tree)]
    return VelocityTerms(v, bias, c)


def free_accelerations(model: RobotModel, art: ArticulatedInertias, qd: Scalars,
                       tau: Scalars) -> Scalars:
    """``qdd`` of the unconstrained system under ``tau``, gravity and the joints' damping
    (scalars)."""
    terms = velocity_terms(art, qd)
    return aba_sweep(art, add_damping(model, tau, qd, -1.0), terms.bias, terms.c,
                     gravity_acceleration(model))


def aba(model: RobotModel, q: Any, qd: Any, tau: Any) -> Any:
    """Forward dynamics ``qdd = M^-1 (tau - C qd - G - D qd)`` ``(nq,)`` by the ABA (``D``
    the joints' damping, :func:`gaitopt.dynamics.rnea.add_damping`).

    ``tau`` ``(nq,)`` are generalized forces (see :func:`.actuation.generalized_forces` to get
    them from actuator torques).
    """
    q_s = coordinates(model, q)
    art = articulated_inertias(model, q_s)
    return vector(free_accelerations(model, art, coordinates(model, qd, "qd"),
                                     coordinates(model, tau, "tau")))


def inverse_mass_times(model: RobotModel, q: Any, x: Any) -> Any:
    """``M(q)^-1 x`` ``(nq,)`` by the ABA (zero velocity, no gravity)."""
    art = articulated_inertias(model, coordinates(model, q))
    return vector(aba_sweep(art, coordinates(model, x, "x")))
