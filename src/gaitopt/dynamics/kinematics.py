"""Forward kinematics: link poses, body velocities and accelerations, and points on links.

Frames (see :mod:`gaitopt.robot.model`): every link frame has its origin at the link's
proximal joint (the base point for the base) and is rotated by the link's absolute angle. A
point on a link is given in its link frame (``Link.local_point(along, across)``, metres).
Results about points are in world coordinates: positions (m), velocities (m/s) and classical
accelerations (m/s^2, the second time derivative of the world position).

Every function takes numbers or CasADi symbols (see :mod:`.backend`); vectors come back as
``np.ndarray`` for numbers and as CasADi columns for symbols.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.dynamics.backend import Scalar, Scalars, as_scalars, matrix, vector
from gaitopt.dynamics.spatial import (
    ZERO3,
    Transform,
    Vec3,
    add3,
    cross_motion,
    motion_to_child,
    unit3,
)
from gaitopt.dynamics.tree import (
    Body,
    bodies,
    contact_point,
    holds,
    joint_transforms,
    link_index,
)
from gaitopt.robot.model import BASE_X, BASE_Y, RobotModel

Point2 = tuple[Scalar, Scalar]


def coordinates(model: RobotModel, x: Any, name: str = "q") -> Scalars:
    """A generalized-coordinate-sized vector (``q``, ``qd``, ``qdd``, ``tau``) as scalars."""
    return as_scalars(x, model.nq, name, model.coordinate_names)


def local_point(point_local: Any) -> Point2:
    p = as_scalars(point_local, 2, "point_local", ("x", "y in the link frame, m"))
    return (p[0], p[1])


@dataclass(frozen=True)
class Pose:
    """A link frame in the world: ``c, s`` = cos, sin of its absolute angle, ``origin`` (m)."""

    angle: Scalar
    c: Scalar
    s: Scalar
    origin: Point2

    def to_world(self, p_local: Point2) -> Point2:
        """World coordinates of a point given in this frame."""
        return (self.origin[0] + self.c * p_local[0] - self.s * p_local[1],
                self.origin[1] + self.s * p_local[0] + self.c * p_local[1])

    def rotate(self, v_local: Point2) -> Point2:
        """A free vector given in this frame, in world coordinates."""
        return (self.c * v_local[0] - self.s * v_local[1],
                self.s * v_local[0] + self.c * v_local[1])


def link_poses(model: RobotModel, q: Scalars, x: Sequence[Transform]) -> list[Pose]:
    """World poses of every link (link order), from ``q`` and the joint transforms ``x``
    of :func:`gaitopt.dynamics.tree.joint_transforms` (their cos/sin are reused)."""
    base_x = x[model.coordinate_of_link(0)]
    poses = [Pose(q[model.coordinate_of_link(0)], base_x.c, base_x.s,
                  (q[BASE_X], q[BASE_Y]))]
    for i in range(1, len(model.links)):
        parent = poses[model.parent_index(i)]
        k = model.coordinate_of_link(i)
        xk = x[k]
        origin = parent.to_world((xk.rx, xk.ry))
        poses.append(Pose(parent.angle + q[k], parent.c * xk.c - parent.s * xk.s,
                          parent.s * xk.c + parent.c * xk.s, origin))
    return poses


def body_velocities(tree: Sequence[Body], x: Sequence[Transform], qd: Scalars) -> list[Vec3]:
    """Spatial velocity ``v_k = X_k v_parent + S_k qd_k`` of every body, body coordinates."""
    v: list[Vec3] = []
    for k, body in enumerate(tree):
        v_parent = v[body.parent] if body.parent >= 0 else ZERO3
        joint = unit3(body.axis)
        v.append(add3(motion_to_child(x[k], v_parent),
                      (joint[0] * qd[k], joint[1] * qd[k], joint[2] * qd[k])))
    return v


def velocity_products(tree: Sequence[Body], v: Sequence[Vec3], qd: Scalars) -> list[Vec3]:
    """``c_k = v_k x S_k qd_k``: the velocity-product acceleration of every body."""
    out: list[Vec3] = []
    for k, body in enumerate(tree):
        joint = unit3(body.axis)
        out.append(cross_motion(v[k], (joint[0] * qd[k], joint[1] * qd[k], joint[2] * qd[k])))
    return out


def body_accelerations(tree: Sequence[Body], x: Sequence[Transform], c: Sequence[Vec3],
                       qdd: Scalars, a_root: Vec3 = ZERO3) -> list[Vec3]:
    """Spatial acceleration ``a_k = X_k a_parent + S_k qdd_k + c_k`` of every body.

    ``a_root`` is the world's spatial acceleration: zero for true accelerations, ``-gravity``
    (Featherstone's trick) inside the dynamics algorithms.
    """
    a: list[Vec3] = []
    for k, body in enumerate(tree):
        a_parent = a[body.parent] if body.parent >= 0 else a_root
        joint = unit3(body.axis)
        a.append(add3(add3(motion_to_child(x[k], a_parent), c[k]),
                      (joint[0] * qdd[k], joint[1] * qdd[k], joint[2] * qdd[k])))
    return a


def point_velocity_world(pose: Pose, v_body: Vec3, p_local: Point2) -> Point2:
    """World velocity of a point fixed in a link, from the link's spatial velocity."""
    w, vx, vy = v_body
    return pose.rotate((vx - w * p_local[1], vy + w * p_local[0]))


def point_acceleration_world(pose: Pose, v_body: Vec3, a_body: Vec3, p_local: Point2) -> Point2:
    """Classical world acceleration of a point fixed in a link: the spatial acceleration at the
    point plus ``omega x v_point``."""
    w, vx, vy = v_body
    dw, ax, ay = a_body
    vpx, vpy = vx - w * p_local[1], vy + w * p_local[0]
    return pose.rotate((ax - dw * p_local[1] - w * vpy, ay + dw * p_local[0] + w * vpx))


def point_jacobian_rows(model: RobotModel, poses: Sequence[Pose], link: int,
                        p_world: Point2) -> tuple[Scalars, Scalars]:
    """Rows ``(dx/dq, dy/dq)`` of the world position of a point on ``link`` at ``p_world``.

    Column of ``x``: ``(1, 0)``; of ``y``: ``(0, 1)``; of a revolute coordinate of a link ``j``
    on the chain from the base to ``link``: ``z x (p - o_j)`` with ``o_j`` the origin of link
    ``j``; other columns are zero.
    """
    row_x: Scalars = [0.0] * model.nq
    row_y: Scalars = [0.0] * model.nq
    row_x[BASE_X], row_y[BASE_Y] = 1.0, 1.0
    for j in model.chain(link):
        k = model.coordinate_of_link(j)
        o = poses[j].origin
        row_x[k] = -(p_world[1] - o[1])
        row_y[k] = p_world[0] - o[0]
    return row_x, row_y


# -- public API --------------------------------------------------------------------------------

def link_angles(model: RobotModel, q: Any) -> Any:
    """Absolute angle (rad) of every link, in link order, shape ``(n_links,)``."""
    q_s = coordinates(model, q)
    poses = link_poses(model, q_s, joint_transforms(bodies(model), q_s))
    return vector([p.angle for p in poses])


@dataclass(frozen=True)
class LinkFrame:
    """A link frame in the world: ``origin`` ``(2,)`` in m, ``angle`` in rad."""

    name: str
    origin: Any
    angle: Any


def link_frames(model: RobotModel, q: Any) -> tuple[LinkFrame, ...]:
    """World origin and absolute angle of every link frame (for drawing)."""
    q_s = coordinates(model, q)
    poses = link_poses(model, q_s, joint_transforms(bodies(model), q_s))
    return tuple(LinkFrame(link.name, vector(list(p.origin)), p.angle)
                 for link, p in zip(model.links, poses, strict=True))


def point_position(model: RobotModel, q: Any, link: str | int, point_local: Any) -> Any:
    """World position ``(2,)`` (m) of the point ``point_local`` (link frame, m) on ``link``."""
    i = link_index(model, link)
    p = local_point(point_local)
    q_s = coordinates(model, q)
    poses = link_poses(model, q_s, joint_transforms(bodies(model), q_s))
    return vector(list(poses[i].to_world(p)))


def point_velocity(model: RobotModel, q: Any, qd: Any, link: str | int,
                   point_local: Any) -> Any:
    """World velocity ``(2,)`` (m/s) of a point fixed on ``link``."""
    i = link_index(model, link)
    p = local_point(point_local)
    q_s, qd_s = coordinates(model, q), coordinates(model, qd, "qd")
    tree = bodies(model)
    x = joint_transforms(tree, q_s)
    v = body_velocities(tree, x, qd_s)
    pose = link_poses(model, q_s, x)[i]
    return vector(list(point_velocity_world(pose, v[model.coordinate_of_link(i)], p)))


def point_acceleration(model: RobotModel, q: Any, qd: Any, qdd: Any, link: str | int,
                       point_local: Any) -> Any:
    """World (classical) acceleration ``(2,)`` (m/s^2) of a point fixed on ``link``:
    ``J qdd + Jdot qd``."""
    i = link_index(model, link)
    p = local_point(point_local)
    q_s, qd_s = coordinates(model, q), coordinates(model, qd, "qd")
    qdd_s = coordinates(model, qdd, "qdd")
    tree = bodies(model)
    x = joint_transforms(tree, q_s)
    v = body_velocities(tree, x, qd_s)
    a = body_accelerations(tree, x, velocity_products(tree, v, qd_s), qdd_s)
    b = model.coordinate_of_link(i)
    pose = link_poses(model, q_s, x)[i]
    return vector(list(point_acceleration_world(pose, v[b], a[b], p)))


def point_jacobian(model: RobotModel, q: Any, link: str | int, point_local: Any) -> Any:
    """Jacobian ``(2, nq)`` of the world position of a point on ``link`` w.r.t. ``q``."""
    i = link_index(model, link)
    p = local_point(point_local)
    q_s = coordinates(model, q)
    poses = link_poses(model, q_s, joint_transforms(bodies(model), q_s))
    return matrix(list(point_jacobian_rows(model, poses, i, poses[i].to_world(p))))


def contact_position(model: RobotModel, q: Any, contact: str) -> Any:
    """World position ``(2,)`` (m) of a contact point."""
    i, p = contact_point(model, contact)
    return point_position(model, q, i, p)


def contact_velocity(model: RobotModel, q: Any, qd: Any, contact: str) -> Any:
    """World velocity ``(2,)`` (m/s) of a contact point."""
    i, p = contact_point(model, contact)
    return point_velocity(model, q, qd, i, p)


def contact_acceleration(model: RobotModel, q: Any, qd: Any, qdd: Any, contact: str) -> Any:
    """World acceleration ``(2,)`` (m/s^2) of a contact point."""
    i, p = contact_point(model, contact)
    return point_acceleration(model, q, qd, qdd, i, p)


def contact_jacobian(model: RobotModel, q: Any, contacts: str | Sequence[str]) -> Any:
    """Stacked Jacobian ``(2 * n_contacts, nq)`` of the listed contact points (rows
    ``x_1, y_1, x_2, y_2, ...``, world frame). A single name gives ``(2, nq)``; a hold spec
    ``name:y`` contributes its ``y`` row only (:func:`gaitopt.dynamics.tree.holds`)."""
    q_s = coordinates(model, q)
    poses = link_poses(model, q_s, joint_transforms(bodies(model), q_s))
    rows: list[Scalars] = []
    for hold in holds(model, contacts):
        i, p = contact_point(model, hold.name)
        point_rows = point_jacobian_rows(model, poses, i, poses[i].to_world(p))
        rows.extend(point_rows[a] for a in hold.axes)
    return matrix(rows, model.nq)
