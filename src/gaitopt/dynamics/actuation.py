"""From actuator torques ``u`` to generalized forces ``tau = B u``.

``u`` has one entry per actuator of the model, in model order (N m). A joint actuator applies
``+u`` to the child link and ``-u`` to the parent, so it appears as ``+u`` on that joint's
coordinate only. A contact (ankle) actuator applies a pure moment ``+u`` from the ground to the
link carrying the contact point; its generalized force is ``J_omega^T u`` with ``J_omega`` the
link's angular-velocity Jacobian (1 on the base angle and on every joint from the base to that
link). It acts only while its contact point is held on the ground (listed in
``contacts_held``); otherwise its column of ``B`` is zero.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from gaitopt.dynamics.backend import Scalars, as_scalars, dot, matrix, vector
from gaitopt.dynamics.kinematics import coordinates
from gaitopt.dynamics.tree import holds
from gaitopt.robot.model import RobotModel


def actuation_rows(model: RobotModel, contacts_held: Sequence[str]) -> list[list[float]]:
    """``B`` ``(nq, nu)`` as a list of rows of floats (it does not depend on ``q``)."""
    held = [h.name for h in holds(model, contacts_held, "contacts_held")]
    b = [[0.0] * model.nu for _ in range(model.nq)]
    for j, act in enumerate(model.actuators):
        if act.joint is not None:
            b[model.joint_coordinate(act.joint)][j] = 1.0
        elif act.contact in held:
            link = model.link_index(model.contact(act.contact).link)
            for i in model.chain(link):
                b[model.coordinate_of_link(i)][j] = 1.0
    return b


def actuation_matrix(model: RobotModel, q: Any, contacts_held: Sequence[str] = ()) -> Any:
    """The actuation matrix ``B`` ``(nq, nu)``: ``tau = B u``. ``q`` ``(nq,)`` is checked but
    ``B`` is constant for revolute joints and pure ankle moments."""
    coordinates(model, q)
    return matrix(actuation_rows(model, contacts_held), model.nu)


def generalized_forces_scalars(model: RobotModel, u: Scalars,
                               contacts_held: Sequence[str]) -> Scalars:
    return [dot(row, u) for row in actuation_rows(model, contacts_held)]


def generalized_forces(model: RobotModel, q: Any, u: Any,
                       contacts_held: Sequence[str] = ()) -> Any:
    """``tau = B u`` ``(nq,)`` for actuator torques ``u`` ``(nu,)`` (N m)."""
    coordinates(model, q)
    u_s = as_scalars(u, model.nu, "u", tuple(a.name for a in model.actuators))
    return vector(generalized_forces_scalars(model, u_s, contacts_held))
