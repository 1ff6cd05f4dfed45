"""Energy, centre of mass and momentum of the whole body.

* ``kinetic_energy = 1/2 sum_k v_k . I_k v_k = 1/2 qd^T M qd`` (J),
* ``potential_energy = -sum_i m_i g . c_i`` (J, zero at ``y = 0`` for ``g = (0, -9.81)``),
* ``center_of_mass = sum_i m_i c_i / sum_i m_i`` ``(2,)`` (m, world),
* ``angular_momentum(point) = sum_i [I_i omega_i + m_i (c_i - point) x v_ci]`` (kg m^2/s,
  about z through the world ``point``),
* ``linear_momentum = sum_i m_i v_ci`` ``(2,)`` (kg m/s, world).
"""

from __future__ import annotations

from typing import Any

from gaitopt.dynamics.backend import Scalar, Scalars, as_scalars, vector
from gaitopt.dynamics.kinematics import (
    Pose,
    body_velocities,
    coordinates,
    link_poses,
    point_velocity_world,
)
from gaitopt.dynamics.spatial import Vec3, dot3, inertia_times
from gaitopt.dynamics.tree import bodies, joint_transforms
from gaitopt.robot.model import RobotModel


def _state(model: RobotModel, q: Any, qd: Any | None
           ) -> tuple[list[Pose], list[Vec3] | None]:
    q_s = coordinates(model, q)
    tree = bodies(model)
    x = joint_transforms(tree, q_s)
    v = body_velocities(tree, x, coordinates(model, qd, "qd")) if qd is not None else None
    return link_poses(model, q_s, x), v


def kinetic_energy_scalars(model: RobotModel, q: Scalars, qd: Scalars) -> Scalar:
    tree = bodies(model)
    v = body_velocities(tree, joint_transforms(tree, q), qd)
    total: Scalar = 0.0
    for k, body in enumerate(tree):
        total = total + 0.5 * dot3(v[k], inertia_times(body.inertia, v[k]))
    return total


def kinetic_energy(model: RobotModel, q: Any, qd: Any) -> Any:
    """Kinetic energy (J)."""
    return kinetic_energy_scalars(model, coordinates(model, q), coordinates(model, qd, "qd"))


def potential_energy(model: RobotModel, q: Any) -> Any:
    """Gravitational potential energy ``-sum m_i g . c_i`` (J)."""
    poses, _ = _state(model, q, None)
    gx, gy = model.gravity
    total: Scalar = 0.0
    for link, pose in zip(model.links, poses, strict=True):
        c = pose.to_world(link.com_local)
        total = total - link.mass * (gx * c[0] + gy * c[1])
    return total


def total_energy(model: RobotModel, q: Any, qd: Any) -> Any:
    """Kinetic plus potential energy (J)."""
    return kinetic_energy(model, q, qd) + potential_energy(model, q)


def center_of_mass(model: RobotModel, q: Any) -> Any:
    """World position ``(2,)`` of the centre of mass (m)."""
    poses, _ = _state(model, q, None)
    sx: Scalar = 0.0
    sy: Scalar = 0.0
    for link, pose in zip(model.links, poses, strict=True):
        c = pose.to_world(link.com_local)
        sx, sy = sx + link.mass * c[0], sy + link.mass * c[1]
    return vector([sx / model.total_mass, sy / model.total_mass])


def linear_momentum(model: RobotModel, q: Any, qd: Any) -> Any:
    """Total linear momentum ``(2,)`` (kg m/s, world)."""
    poses, v = _state(model, q, qd)
    assert v is not None
    px: Scalar = 0.0
    py: Scalar = 0.0
    for i, (link, pose) in enumerate(zip(model.links, poses, strict=True)):
        vc = point_velocity_world(pose, v[model.coordinate_of_link(i)], link.com_local)
        px, py = px + link.mass * vc[0], py + link.mass * vc[1]
    return vector([px, py])


def angular_momentum(model: RobotModel, q: Any, qd: Any, point: Any = (0.0, 0.0)) -> Any:
    """Angular momentum about z through the world ``point`` ``(2,)`` (kg m^2/s)."""
    poses, v = _state(model, q, qd)
    assert v is not None
    o = as_scalars(point, 2, "point", ("x", "y"))
    total: Scalar = 0.0
    for i, (link, pose) in enumerate(zip(model.links, poses, strict=True)):
        vb = v[model.coordinate_of_link(i)]
        c = pose.to_world(link.com_local)
        vc = point_velocity_world(pose, vb, link.com_local)
        rx, ry = c[0] - o[0], c[1] - o[1]
        total = total + link.inertia * vb[0] + link.mass * (rx * vc[1] - ry * vc[0])
    return total
