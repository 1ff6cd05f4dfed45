"""Inverse dynamics by the recursive Newton-Euler algorithm (RNEA).

``tau = M(q) qdd + C(q, qd) qd + G(q) - tau_ext`` (paper eq. 1 solved for the torques), with
gravity ``model.gravity`` entering as the world's spatial acceleration ``a_0 = -g``
(Featherstone's trick). Per body ``k`` (body coordinates, see :mod:`.tree`)::

    v_k = X_k v_parent + S_k qd_k
    a_k = X_k a_parent + S_k qdd_k + v_k x S_k qd_k
    f_k = I_k a_k + v_k x* I_k v_k            (net force on body k)
    tau_k = S_k^T f_k ;  f_parent += X_k^T f_k   (outward to inward)

``tau`` has shape ``(nq,)``: the generalized force on each coordinate (N on ``x``, ``y`` in the
world frame, N m on the angles).
"""

from __future__ import annotations

from typing import Any

from gaitopt.dynamics.backend import Scalars, vector
from gaitopt.dynamics.kinematics import (
    body_accelerations,
    body_velocities,
    coordinates,
    velocity_products,
)
from gaitopt.dynamics.spatial import (
    Vec3,
    add3,
    cross_force,
    force_to_parent,
    inertia_times,
)
from gaitopt.dynamics.tree import bodies, joint_transforms
from gaitopt.robot.model import RobotModel


def gravity_acceleration(model: RobotModel) -> Vec3:
    """The world's fictitious spatial acceleration ``-g`` (no angular part), m/s^2."""
    gx, gy = model.gravity
    return (0.0, -gx, -gy)


def rnea_scalars(model: RobotModel, q: Scalars, qd: Scalars, qdd: Scalars,
                 *, gravity: bool = True) -> Scalars:
    """:func:`rnea` on scalar lists, without ``tau_ext`` (``gravity=False`` drops ``G``)."""
    tree = bodies(model)
    x = joint_transforms(tree, q)
    v = body_velocities(tree, x, qd)
    a_root = gravity_acceleration(model) if gravity else (0.0, 0.0, 0.0)
    a = body_accelerations(tree, x, velocity_products(tree, v, qd), qdd, a_root)
    f: list[Vec3] = []
    for k, body in enumerate(tree):
        h = inertia_times(body.inertia, v[k])
        f.append(add3(inertia_times(body.inertia, a[k]), cross_force(v[k], h)))
    tau: Scalars = [0.0] * len(tree)
    for k in reversed(range(len(tree))):
        body = tree[k]
        tau[k] = f[k][body.axis]
        if body.parent >= 0:
            f[body.parent] = add3(f[body.parent], force_to_parent(x[k], f[k]))
    return add_damping(model, tau, qd, +1.0)


def add_damping(model: RobotModel, tau: Scalars, qd: Scalars, sign: float) -> Scalars:
    """``tau + sign D qd`` with ``D = diag(b)`` the joints' damping
    (:attr:`~gaitopt.robot.model.RobotModel.coordinate_damping`, N m s/rad): ``+1`` in the
    RNEA (the generalized force that also overcomes the damping), ``-1`` where forces drive
    the ABA (the damping's passive torque ``-D qd`` joins them). Coordinates without damping
    are passed through untouched (the same expressions as without this term)."""
    out = list(tau)
    for i, b in enumerate(model.coordinate_damping):
        if b:
            out[i] = out[i] + sign * b * qd[i]
    return out


def rnea(model: RobotModel, q: Any, qd: Any, qdd: Any, tau_ext: Any = None) -> Any:
    """Generalized forces ``tau (nq,)`` that produce ``qdd`` at state ``(q, qd)``:
    ``M qdd + C qd + G + D qd`` (``D`` the joints' damping, :func:`add_damping`).

    ``tau_ext`` (optional, ``(nq,)``) are generalized forces from outside the joints (for
    example ``J_c^T f_c`` of contact forces); the result is then ``M qdd + C + G - tau_ext``.
    """
    q_s, qd_s = coordinates(model, q), coordinates(model, qd, "qd")
    tau = rnea_scalars(model, q_s, qd_s, coordinates(model, qdd, "qdd"))
    if tau_ext is not None:
        ext = coordinates(model, tau_ext, "tau_ext")
        tau = [t - e for t, e in zip(tau, ext, strict=True)]
    return vector(tau)


def bias_forces(model: RobotModel, q: Any, qd: Any) -> Any:
    """``C(q, qd) qd + G(q) + D qd`` ``(nq,)``: Coriolis, centrifugal, gravity and joint
    damping generalized forces (RNEA with ``qdd = 0``)."""
    q_s, qd_s = coordinates(model, q), coordinates(model, qd, "qd")
    return vector(rnea_scalars(model, q_s, qd_s, [0.0] * model.nq))


def gravity_forces(model: RobotModel, q: Any) -> Any:
    """``G(q)`` ``(nq,)``: the generalized gravity forces (RNEA with ``qd = qdd = 0``)."""
    zeros = [0.0] * model.nq
    return vector(rnea_scalars(model, coordinates(model, q), zeros, zeros))
