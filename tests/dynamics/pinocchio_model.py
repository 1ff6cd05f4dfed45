"""An independent reference: a Pinocchio model built from a gaitopt RobotModel.

Our planar world x-y is Pinocchio's x-y plane; rotations are about z. The floating base is
three Pinocchio joints in series (PX, PY, RZ, all placed at the universe origin). Every other
link is an RZ joint placed at its joint point on the parent joint frame. The 3-D inertia about
the centre of mass is ``diag(I, I, I)`` (only the z entry matters for planar motion). Every
contact point becomes an operational frame named after the contact.

Pinocchio needs its joints in depth-first order (each subtree contiguous in ``v``); our models
only need parents before children. :class:`PinModel` therefore adds the links depth-first and
keeps the permutation ``perm`` with ``q_pin = q[perm]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from gaitopt.robot.model import RobotModel


@dataclass
class PinModel:
    model: pin.Model
    perm: np.ndarray  # q_pin = q_ours[perm]
    joint_of_link: dict[int, int]
    contact_frames: dict[str, int]

    def data(self) -> pin.Data:
        return self.model.createData()

    def to_pin(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(x, dtype=float)[self.perm]

    def from_pin(self, x: np.ndarray) -> np.ndarray:
        """A vector ``(nv,)`` or matrix ``(nv, nv)`` / ``(k, nv)`` from Pinocchio's order."""
        x = np.asarray(x)
        out = np.empty_like(x)
        if x.ndim == 1:
            out[self.perm] = x
        elif x.shape[0] == x.shape[1] == len(self.perm):
            out[np.ix_(self.perm, self.perm)] = x
        else:  # rows are not coordinates (e.g. a Jacobian (k, nv))
            out[:, self.perm] = x
        return out

    def add_point_frame(self, link: int, p_local: tuple[float, float], name: str) -> int:
        """Add an operational frame at ``p_local`` on a link; returns its id."""
        frame = pin.Frame(name, self.joint_of_link[link], 0,
                          pin.SE3(np.eye(3), np.array([*p_local, 0.0])), pin.FrameType.OP_FRAME)
        return self.model.addFrame(frame)


def depth_first(model: RobotModel) -> list[int]:
    children: dict[int, list[int]] = {i: [] for i in range(len(model.links))}
    for i in range(1, len(model.links)):
        children[model.parent_index(i)].append(i)
    order: list[int] = []
    stack = [0]
    while stack:
        i = stack.pop()
        order.append(i)
        stack.extend(reversed(children[i]))
    return order


def build(model: RobotModel) -> PinModel:
    pm = pin.Model()
    pm.gravity.linear = np.array([model.gravity[0], model.gravity[1], 0.0])
    jx = pm.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "base_x")
    jy = pm.addJoint(jx, pin.JointModelPY(), pin.SE3.Identity(), "base_y")
    joint_of_link: dict[int, int] = {}
    perm = [0, 1]
    for i in depth_first(model):
        link = model.links[i]
        if i == 0:
            parent_joint, offset = jy, (0.0, 0.0)
        else:
            p = model.parent_index(i)
            parent_joint = joint_of_link[p]
            assert link.joint is not None
            offset = model.links[p].local_point(*link.joint.at)
        placement = pin.SE3(np.eye(3), np.array([offset[0], offset[1], 0.0]))
        jid = pm.addJoint(parent_joint, pin.JointModelRZ(), placement, f"joint_{link.name}")
        cx, cy = link.com_local
        inertia = pin.Inertia(link.mass, np.array([cx, cy, 0.0]), np.eye(3) * link.inertia)
        pm.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        joint_of_link[i] = jid
        perm.append(model.coordinate_of_link(i))
    frames: dict[str, int] = {}
    for c in model.contacts:
        i = model.link_index(c.link)
        px, py = model.links[i].local_point(*c.at)
        frame = pin.Frame(c.name, joint_of_link[i], 0,
                          pin.SE3(np.eye(3), np.array([px, py, 0.0])), pin.FrameType.OP_FRAME)
        frames[c.name] = pm.addFrame(frame)
    assert pm.nq == model.nq and pm.nv == model.nq
    return PinModel(pm, np.array(perm), joint_of_link, frames)
